// Loading and calling native code (docs/soml.md, "Native compilation"): a library that `vsd-soml compile`
// generated (native_gen.cpp) is opened with dlopen, its module of this program's image is found by the
// image's hash, and its functions replace the VM's for calls (RunCode::native). The callbacks below give
// native code the VM's messages: the same words, the same call stack (native frames reported as they
// unwind, then the VM's).
#include "native.hpp"

#include <dlfcn.h>

#include <bit>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "program_impl.hpp"
#include "vsd/core/error.hpp"
#include "vsd/core/instance.hpp"

namespace vsd::soml {

namespace {

using native::Fault;

ProgramImpl& impl_of(native::Context* c) { return *static_cast<ProgramImpl*>(c->runtime); }

[[noreturn]] void native_fail(native::Context* c, Fault f, std::uint32_t fn, std::uint32_t at, std::int64_t a,
                              std::int64_t b) {
  ProgramImpl& p = impl_of(c);
  p.native_sites_.emplace_back(fn, at);
  p.budget_ = c->budget;
  switch (f) {
    case Fault::Add:
      p.int_overflow(a, "+", b);
    case Fault::Sub:
      p.int_overflow(a, "-", b);
    case Fault::Mul:
      p.int_overflow(a, "*", b);
    case Fault::Div:
      p.int_overflow(a, "/", b);
    case Fault::Neg:
      p.int_overflow("-", a);
    case Fault::Abs:
      p.int_overflow("abs", a);
    case Fault::DivisionByZero:
      p.fail("division by zero");
    case Fault::NullReference:
      p.fail("null reference");
    case Fault::DoubleToInt:
      p.fail("the double " + fmt_double(std::bit_cast<double>(a)) + " does not fit an int");
    case Fault::LoopBudget:
      p.loop_budget_exhausted();
    case Fault::CallBudget:
      p.fail("instruction budget exhausted (" + std::to_string(p.opt_.instruction_budget) +
             " jumps and calls): runaway recursion?");
    case Fault::Depth:
      p.fail("call depth limit (" + std::to_string(p.opt_.max_depth) + ") reached calling " +
             p.image().functions.at(static_cast<std::size_t>(b))->name);
    case Fault::Fail:
      p.fail(p.image().strings.at(static_cast<std::size_t>(b)));
  }
  p.fail("bad native fault");
}

void native_unwind(native::Context* c, std::uint32_t fn, std::uint32_t at) {
  impl_of(c).native_sites_.emplace_back(fn, at);
}

// OP_PRINT of numbers (native code prints nothing else), as the VM writes it.
void native_print(native::Context* c, std::uint32_t index, const native::Reg* regs) {
  ProgramImpl& p = impl_of(c);
  std::ostream& out = p.opt_.out != nullptr ? *p.opt_.out : std::cout;
  const auto& kinds = p.image().print_kinds.at(index);
  std::string line;
  for (std::size_t i = 0; i < kinds.size(); ++i)
    line += kinds[i] == RK::D ? fmt_double(regs[i].d) : std::to_string(regs[i].i);
  out << line << '\n';
}

// Properties and enclosing instances through the VM's own code (read_scalar, write_scalar, enclosing):
// the same checks and errors, the same path of a store. An error passing here gets the instruction's
// frame, as native_fail gives it.
native::Reg native_getp(native::Context* c, std::uint32_t fn, std::uint32_t at, std::uint64_t id,
                        std::uint32_t prop) {
  ProgramImpl& p = impl_of(c);
  try {
    return std::bit_cast<native::Reg>(p.read_scalar(id, prop));
  } catch (...) {
    p.native_sites_.emplace_back(fn, at);
    throw;
  }
}

// The budget comes in and goes back through the Context: a listener of the change may run SOML++ code.
void native_setp(native::Context* c, std::uint32_t fn, std::uint32_t at, std::uint64_t id, std::uint32_t prop,
                 native::Reg v) {
  ProgramImpl& p = impl_of(c);
  p.budget_ = c->budget;
  try {
    p.write_scalar(id, prop, std::bit_cast<Val>(v));
  } catch (...) {
    p.native_sites_.emplace_back(fn, at);
    throw;
  }
  c->budget = p.budget_;
}

std::uint64_t native_outer(native::Context* c, std::uint32_t fn, std::uint32_t at, std::uint64_t id,
                           std::uint32_t parents) {
  ProgramImpl& p = impl_of(c);
  try {
    return p.enclosing(id, static_cast<int>(parents));
  } catch (...) {
    p.native_sites_.emplace_back(fn, at);
    throw;
  }
}

}  // namespace

Val ProgramImpl::call_native(native::Entry e, std::uint64_t self, std::uint64_t mark, const Val* args,
                             std::size_t depth) {
  static_assert(sizeof(Val) == sizeof(native::Reg) && alignof(Val) == alignof(native::Reg));
  nctx_.budget = budget_;  // the callbacks and limits were filled by load_native
  nctx_.consts = consts_.data();
  nctx_.outer_ids = outer_ids_.data();
  native_sites_.clear();
  struct Depth {  // native_depth_ counts this call until it returns or throws
    int& n;
    ~Depth() { --n; }
  } depth_guard{++native_depth_};
  try {
    const native::Reg r = e(&nctx_, static_cast<std::uint32_t>(depth), self, mark,
                            reinterpret_cast<const native::Reg*>(args));  // same layout (asserted above)
    budget_ = nctx_.budget;
    return std::bit_cast<Val>(r);
  } catch (const Error& err) {
    budget_ = nctx_.budget;
    std::string msg = err.what();
    for (const auto& [fn, at] : native_sites_) msg += frame_text(*image().functions.at(fn), at);
    native_sites_.clear();
    throw Error(msg);
  }
}

std::size_t ProgramImpl::load_native(const std::string& path) {
  void* h = ::dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (h == nullptr) {
    const char* why = ::dlerror();
    throw Error("cannot load the SOML++ native library '" + path +
                "': " + (why != nullptr ? why : "unknown"));
  }
  std::shared_ptr<void> lib(h, [](void* x) { ::dlclose(x); });
  void* sym = ::dlsym(h, native::kModulesSymbol);
  if (sym == nullptr)
    throw Error("'" + path + "' is no SOML++ native library (no symbol " + native::kModulesSymbol + ")");
  std::uint32_t n = 0;
  const native::Module* const* mods = reinterpret_cast<native::Modules>(sym)(&n);
  const std::uint64_t want = image_hash(image());
  const native::Module* found = nullptr;
  std::string have;
  for (std::uint32_t i = 0; i < n; ++i) {
    const native::Module& m = *mods[i];
    if (m.abi != native::kNativeAbi)
      throw Error("'" + path + "' was generated for native ABI " + std::to_string(m.abi) +
                  ", this runtime has " + std::to_string(native::kNativeAbi) +
                  ": regenerate it (vsd-soml compile)");
    std::ostringstream hex;
    hex << std::hex << std::setw(16) << std::setfill('0') << m.image_hash;
    have += std::string(have.empty() ? "" : ", ") + m.script + " (" + hex.str() + ")";
    if (m.image_hash == want) found = &m;
  }
  if (found == nullptr) {
    std::ostringstream hex;
    hex << std::hex << std::setw(16) << std::setfill('0') << want;
    throw Error("'" + path + "' holds no native code of this version of " + image().checked->source->name() +
                " (image " + hex.str() + "; it has " + (have.empty() ? "nothing" : have) +
                "): regenerate it with vsd-soml compile");
  }
  for (std::uint32_t i = 0; i < found->count; ++i)
    if (found->functions[i].index >= run_.size() || found->functions[i].entry == nullptr)
      throw Error("'" + path + "': a bad function entry");
  // The callbacks and the depth limit, once (the tables are set per call: call_native).
  nctx_.max_depth = static_cast<std::uint32_t>(opt_.max_depth);
  nctx_.runtime = this;
  nctx_.fail = &native_fail;
  nctx_.unwind = &native_unwind;
  nctx_.print = &native_print;
  nctx_.getp = &native_getp;
  nctx_.setp = &native_setp;
  nctx_.outer = &native_outer;
  for (RunCode& rc : run_) rc.native = nullptr;
  for (std::uint32_t i = 0; i < found->count; ++i)
    run_[found->functions[i].index].native = found->functions[i].entry;
  native_lib_ = std::move(lib);
  native_count_ = found->count;
  return found->count;
}

}  // namespace vsd::soml

namespace vsd::soml {

std::size_t Program::load_native(const std::string& path) { return impl_->load_native(path); }
std::size_t Program::native_functions() const noexcept { return impl_->native_count_; }
std::uint64_t Program::image_hash() const { return soml::image_hash(impl_->image()); }

std::string native_library_source(const std::vector<const Program*>& programs) {
  std::vector<const ProgramImage*> images;
  std::vector<std::string> names;
  for (const Program* p : programs) {
    // const_cast: impl() is non-const, the image is only read.
    const ProgramImpl& impl = const_cast<Program*>(p)->impl();
    images.push_back(&impl.image());
    names.push_back(impl.image().checked->source->name());
  }
  std::ostringstream out;
  native_library_source(out, images, names);
  return out.str();
}

}  // namespace vsd::soml
