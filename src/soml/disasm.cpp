// The disassembler (`vsd-soml disasm`, Program::disassemble): a program image as text, one line per
// instruction, its operands named after their shapes in the opcode table (opcodes.hpp).
#include <algorithm>
#include <cstdio>
#include <sstream>
#include <string>

#include "program_impl.hpp"
#include "vsd/core/meta_method.hpp"
#include "vsd/core/meta_property.hpp"
#include "vsd/core/meta_type.hpp"

namespace vsd::soml {

namespace {

// A string constant as a quoted literal (control characters escaped, long ones cut).
std::string quoted(const std::string& s) {
  std::string out = "\"";
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (i == 60) {
      out += "...";
      break;
    }
    const auto c = static_cast<unsigned char>(s[i]);
    if (c == '"' || c == '\\') {
      out += '\\';
      out += static_cast<char>(c);
    } else if (c == '\n') {
      out += "\\n";
    } else if (c < 0x20 || c == 0x7F) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02x", c);
      out += buf;
    } else {
      out += static_cast<char>(c);
    }
  }
  return out + "\"";
}

template <class T>
const T* at(const std::vector<T>& v, std::size_t i) {
  return i < v.size() ? &v[i] : nullptr;
}

// One operand of shape @p kind with value @p v (@p in for jump targets); what it refers to goes to @p note.
std::string operand(const ProgramImage& img, char kind, std::uint16_t v, const Ins& in, std::string& note) {
  auto add = [&note](const std::string& s) { note += (note.empty() ? "" : ", ") + s; };
  switch (kind) {
    case 'r':
      return "r" + std::to_string(v);
    case 'i':
      return "#" + std::to_string(static_cast<std::int16_t>(v));
    case 'k':
      if (const auto* k = at(img.consts, v)) add("k" + std::to_string(v) + " = " + std::to_string(*k));
      return "k" + std::to_string(v);
    case 's':
      if (const auto* s = at(img.strings, v)) add(quoted(*s));
      return "s" + std::to_string(v);
    case 'p':
      if (const auto* p = at(img.props, v); p != nullptr && p->prop != nullptr) add("." + p->prop->name());
      return "p" + std::to_string(v);
    case 'f':
      if (const auto* f = at(img.functions, v)) add((*f)->name);
      return "f" + std::to_string(v);
    case 'v':
      if (const auto* f = at(img.vslots, v); f != nullptr && *f != nullptr) add("virtual " + (*f)->name);
      return "v" + std::to_string(v);
    case 'c':
      if (const auto* c = at(img.class_metas, v); c != nullptr && *c != nullptr) add((*c)->name());
      return "c" + std::to_string(v);
    case 'm':
      if (const auto* m = at(img.methods, v); m != nullptr && *m != nullptr) add((*m)->name() + "()");
      return "m" + std::to_string(v);
    case 'o':
      return "o" + std::to_string(v);
    case 'y':
      if (const auto* t = at(img.xtypes, v); t != nullptr && *t != nullptr) add((*t)->name());
      return "y" + std::to_string(v);
    case 't':
      return "-> " + std::to_string((static_cast<std::uint32_t>(in.x) << 16) | in.c);
    default:  // 'n'
      return std::to_string(v);
  }
}

}  // namespace

std::string disassemble(const ProgramImage& img) {
  std::ostringstream out;
  const std::string file = img.checked != nullptr ? img.checked->source->name() : "?";
  out << "; " << file << ": " << img.functions.size() << " functions, " << img.consts.size() << " constants, "
      << img.strings.size() << " strings\n";
  for (std::size_t fi = 0; fi < img.functions.size(); ++fi) {
    const Function& f = *img.functions[fi];
    std::uint32_t line = 0;  // the first line its code computes (0: none, e.g. empty initialisers)
    for (const Function::Pos& p : f.positions)
      if (p.line != 0 && (line == 0 || p.line < line)) line = p.line;
    out << "\nfunction f" << fi << " " << f.name << " (" << file;
    if (line != 0) out << ":" << line;
    out << ")\n";
    out << "  params " << f.nparams << ", registers " << f.nregs << ", result "
        << (f.result == RK::None ? std::string("void") : f.result_type.name()) << ", " << f.code.size()
        << " instructions\n";
    for (const Function::Local& l : f.locals)
      out << "  local r" << l.slot << " " << l.name << ": " << l.type.name() << " [" << l.from << ", " << l.to
          << ")\n";
    for (std::size_t i = 0; i < f.code.size(); ++i) {
      const Ins& in = f.code[i];
      const OpInfo op = op_info(in.op);
      std::string ops, note;
      const std::uint16_t v[3] = {in.a, in.b, in.c};
      for (int k = 0; k < 3; ++k) {
        if (op.shape[static_cast<std::size_t>(k)] == '-') continue;
        ops +=
            (ops.empty() ? "" : ", ") + operand(img, op.shape[static_cast<std::size_t>(k)], v[k], in, note);
      }
      if (in.x != 0 && op.shape[2] != 't') ops += (ops.empty() ? "x=" : ", x=") + std::to_string(in.x);
      std::string text = std::to_string(i);
      text = std::string(text.size() < 7 ? 7 - text.size() : 0, ' ') + text + "  " + std::string(op.name);
      text.resize(std::max<std::size_t>(text.size() + 1, 18), ' ');
      text += ops;
      if (text.size() < 40) text.resize(40, ' ');
      out << text << " ; ";
      if (i < f.positions.size() && f.positions[i].line != 0)
        out << f.positions[i].line << ":" << f.positions[i].column;
      else
        out << "-";
      if (!note.empty()) out << "  " << note;
      out << "\n";
    }
  }
  if (!img.consts.empty()) {
    out << "\nconstants\n";
    for (std::size_t i = 0; i < img.consts.size(); ++i) out << "  k" << i << " = " << img.consts[i] << "\n";
  }
  if (!img.strings.empty()) {
    out << "\nstrings\n";
    for (std::size_t i = 0; i < img.strings.size(); ++i)
      out << "  s" << i << " = " << quoted(img.strings[i]) << "\n";
  }
  return out.str();
}

}  // namespace vsd::soml
