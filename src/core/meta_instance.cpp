// MetaInstance, MetaProperty, MetaMethod, ClassBuilder and Value: the meta-information layer (M2).
#include "vsd/core/meta_instance.hpp"

#include <algorithm>
#include <iterator>
#include <cmath>
#include <cstring>
#include <limits>
#include <mutex>

#include "vsd/core/error.hpp"
#include "vsd/core/instance.hpp"
#include "vsd/core/registry.hpp"
#include "vsd/core/text.hpp"

namespace vsd {

namespace detail {

template <class T>
void NameTable<T>::build(const std::vector<std::pair<std::string_view, const T*>>& entries) {
  std::size_t cap = 4;
  while (cap < entries.size() * 2) cap *= 2;
  entries_.assign(cap, Entry{});
  mask_ = cap - 1;
  for (const auto& [name, item] : entries) {
    const NameKey k(name);
    for (std::uint64_t i = k.hash & mask_;; i = (i + 1) & mask_) {
      Entry& e = entries_[i];
      if (e.item == nullptr) {
        e = Entry{k, name, item};
        break;
      }
      if (e.name == name) {  // a later entry (subclass, own name) wins
        e.item = item;
        break;
      }
    }
  }
}

template class NameTable<MetaProperty>;
template class NameTable<MetaMethod>;

namespace {
std::atomic<std::size_t> next_meta_index{0};
std::mutex derived_mutex;  // guards every MetaInstance's list of subclasses
std::size_t align_up(std::size_t v, std::size_t a) { return (v + a - 1) / a * a; }
}  // namespace

}  // namespace detail

// ---- MetaInstance -----------------------------------------------------------------------------------------

MetaInstance::MetaInstance(std::string name, const MetaInstance* base, std::size_t size, std::size_t align,
                           Construct construct, Configure configure)
    : name_(std::move(name)),
      base_(base),
      builtin_(this),
      size_(size),
      align_(align),
      depth_(base != nullptr ? base->depth_ + 1 : 0),
      index_(detail::next_meta_index.fetch_add(1)),
      construct_(construct) {
  if (configure != nullptr) configure(*this);
  finish();
  link_to_base();
}

MetaInstance::MetaInstance(std::string name, const MetaInstance& base, bool abstract)
    : name_(std::move(name)),
      base_(&base),
      builtin_(base.builtin_),
      size_(base.size_),
      align_(base.align_),
      depth_(base.depth_ + 1),
      index_(detail::next_meta_index.fetch_add(1)),
      construct_(base.builtin_->construct_),
      runtime_(true),
      abstract_(abstract) {}

MetaInstance::~MetaInstance() { unlink_from_base(); }

void MetaInstance::link_to_base() {
  if (base_ == nullptr) return;
  std::lock_guard lock(detail::derived_mutex);
  const_cast<MetaInstance*>(base_)->derived_.push_back(this);
}

void MetaInstance::unlink_from_base() noexcept {
  if (base_ == nullptr) return;
  std::lock_guard lock(detail::derived_mutex);
  auto& d = const_cast<MetaInstance*>(base_)->derived_;
  // Searched from the back: classes mostly go in the reverse order they came (a registry's teardown, a
  // failed load's definitions), so each is found at once however many subclasses the base has.
  const auto it = std::find(d.rbegin(), d.rend(), this);
  if (it != d.rend()) d.erase(std::next(it).base());
}

std::vector<const MetaInstance*> MetaInstance::derived() const {
  std::lock_guard lock(detail::derived_mutex);
  return derived_;
}

MetaProperty& MetaInstance::add_property(std::unique_ptr<MetaProperty> p) {
  if (own_names_.contains(p->name()))
    detail::throw_error("class '" + name_ + "' declares property '" + p->name() + "' twice");
  if (base_ != nullptr && base_->find_property(p->name()) != nullptr)
    detail::throw_error("class '" + name_ + "' redeclares inherited property '" + p->name() + "'");
  p->owner_ = this;
  if (own_props_.size() == own_props_.capacity())  // nothing below may fail once the name is in the set
    own_props_.reserve(std::max<std::size_t>(8, 2 * own_props_.size()));
  own_names_.insert(p->name());
  own_props_.push_back(std::move(p));
  return *own_props_.back();
}

MetaMethod& MetaInstance::add_method(std::unique_ptr<MetaMethod> m) {
  for (const auto& q : own_methods_)
    if (q->name() == m->name())
      detail::throw_error("class '" + name_ + "' declares method '" + m->name() + "' twice");
  m->owner_ = this;
  own_methods_.push_back(std::move(m));
  return *own_methods_.back();
}

void MetaInstance::set_slot(std::size_t slot, const MetaProperty* p) {
  if (slots_.size() <= slot) slots_.resize(slot + 1, nullptr);
  slots_[slot] = p;
}

void MetaInstance::finish() {
  props_.clear();
  methods_.clear();
  ancestors_.clear();
  if (base_ != nullptr) {
    props_ = base_->props_;
    methods_ = base_->methods_;
    ancestors_ = base_->ancestors_;
  }
  ancestors_.push_back(this);
  runtime_chain_.clear();
  for (const MetaInstance* m = this; m != nullptr && m->runtime_; m = m->base_) runtime_chain_.push_back(m);
  for (std::size_t i = 0; i < own_props_.size(); ++i) {
    own_props_[i]->index_ = props_.size();
    props_.push_back(own_props_[i].get());
  }
  for (const auto& m : own_methods_) {
    auto same = std::find_if(methods_.begin(), methods_.end(),
                             [&](const MetaMethod* x) { return x->name() == m->name(); });
    if (same != methods_.end()) {
      *same = m.get();  // a subclass's method hides the base's
    } else {
      methods_.push_back(m.get());
    }
  }
  ref_props_.clear();
  std::vector<std::pair<std::string_view, const MetaProperty*>> names;
  for (const MetaProperty* p : props_) {
    if (p->type().is_reference()) ref_props_.push_back(p);
    for (const auto& alias : p->aliases()) names.emplace_back(alias, p);
  }
  for (const MetaProperty* p : props_) names.emplace_back(p->name(), p);  // real names win over aliases
  prop_table_.build(names);
  std::vector<std::pair<std::string_view, const MetaMethod*>> mnames;
  for (const MetaMethod* m : methods_) mnames.emplace_back(m->name(), m);
  method_table_.build(mnames);
}

void MetaInstance::throw_no_property(std::string_view name) const {
  detail::throw_error("class '" + name_ + "' has no property '" + std::string(name) + "'");
}

const MetaMethod& MetaInstance::method(std::string_view name) const {
  if (const MetaMethod* m = find_method(name)) return *m;
  detail::throw_error("class '" + name_ + "' has no method '" + std::string(name) + "'");
}

Value MetaInstance::call(Instance& self, std::string_view name, std::span<const Value> args) const {
  if (!self.meta().is_a(*this))
    detail::throw_error("cannot call " + name_ + "::" + std::string(name) + " on an instance of '" +
                        self.meta().name() + "'");
  return method(name).invoke(self, args);
}

SimStateInstance* MetaInstance::construct(void* memory) const {
  if (is_abstract()) detail::throw_error("class '" + name_ + "' is abstract and cannot be instantiated");
  SimStateInstance* obj = builtin_->construct_(memory);
  VSD_ASSERT(static_cast<void*>(obj) == memory, "the SimStateInstance part must start the object");
  // Run-time properties, root-most class first, each from its default value.
  const std::vector<const MetaInstance*>& chain = runtime_chain_;
  std::size_t built = 0;
  std::size_t built_class = 0;
  try {
    for (auto it = chain.rbegin(); it != chain.rend(); ++it, ++built_class) {
      built = 0;
      for (const auto& p : (*it)->own_props_) {
        void* at = static_cast<char*>(memory) + p->offset();
        p->type().copy_construct(at, p->default_value().data());
        ++built;
      }
    }
  } catch (...) {
    // Unwind what was built, then the C++ part.
    for (std::size_t c = 0; c <= built_class && c < chain.size(); ++c) {
      const MetaInstance* m = chain[chain.size() - 1 - c];
      const std::size_t n = c == built_class ? built : m->own_props_.size();
      for (std::size_t i = n; i-- > 0;)
        m->own_props_[i]->type().destroy(static_cast<char*>(memory) + m->own_props_[i]->offset());
    }
    obj->~SimStateInstance();
    throw;
  }
  obj->set_meta(*this);
  for (const MetaProperty* p : ref_props_) {
    void* at = static_cast<char*>(memory) + p->offset();
    detail::RefBinding::bind(at, p->type().is_ref_list(), obj, p);
  }
  // Only run-time classes are counted: an atomic add costs more than the rest of a pooled create.
  if (runtime_) live_.fetch_add(1, std::memory_order_relaxed);
  return obj;
}

void MetaInstance::destruct(SimStateInstance* obj) const noexcept {
  for (const MetaInstance* m = this; m != nullptr && m->runtime_; m = m->base_)
    for (std::size_t i = m->own_props_.size(); i-- > 0;)
      m->own_props_[i]->type().destroy(reinterpret_cast<char*>(obj) + m->own_props_[i]->offset());
  obj->~SimStateInstance();
  if (runtime_) live_.fetch_sub(1, std::memory_order_relaxed);
}

void MetaInstance::destroy(SimStateInstance* obj) const noexcept {
  destruct(obj);
  ::operator delete(static_cast<void*>(obj), std::align_val_t(align_));
}

// ---- ClassBuilder -----------------------------------------------------------------------------------------

ClassBuilder::ClassBuilder(std::string name, const MetaInstance& base)
    : meta_(new MetaInstance(std::move(name), base, false)) {
  if (base.builtin_->construct_ == nullptr && !base.is_a(SimStateInstance::static_meta()))
    detail::throw_error("run-time class '" + meta_->name() +
                        "' needs a base derived from SimStateInstance, not '" + base.name() + "'");
  // Each class keeps its ancestors and the properties of all of them: a chain of classes costs the square
  // of its length, so a program (or a file) cannot make one without end.
  if (meta_->depth_ > MetaInstance::max_depth)
    detail::throw_error("run-time class '" + meta_->name() + "' would derive from more than " +
                        std::to_string(MetaInstance::max_depth) + " classes (its base '" + base.name() +
                        "' is " + std::to_string(base.depth_) + " deep)");
}

namespace {
// Property names are identifiers: they are JSON keys and script names, and never collide with the
// "@id"/"@class" members of a saved instance.
void check_property_name(const std::string& cls, const std::string& name) {
  auto head = [](char c) { return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || c == '_'; };
  bool ok = !name.empty() && head(name[0]);
  for (std::size_t i = 1; ok && i < name.size(); ++i)
    ok = head(name[i]) || (name[i] >= '0' && name[i] <= '9');
  if (!ok)
    detail::throw_error("class '" + cls + "': '" + name +
                        "' is not a property name (letters, digits and '_', not starting with a digit)");
}
}  // namespace

ClassBuilder& ClassBuilder::property(std::string name, const MetaType& type, Value default_value,
                                     PropertyFlags flags) {
  check_property_name(meta_->name(), name);
  if (default_value.empty()) {
    default_value = Value(type);
  } else if (default_value.type() != &type) {
    default_value = default_value.convert_to(type);
  }
  MetaInstance& m = *meta_;
  const std::size_t offset = detail::align_up(m.size_, type.alignment());
  auto p = std::make_unique<MetaProperty>(std::move(name), type, flags, offset, std::move(default_value));
  m.add_property(std::move(p));
  m.size_ = offset + type.size();
  m.align_ = std::max(m.align_, type.alignment());
  return *this;
}

ClassBuilder& ClassBuilder::method(std::string name, std::vector<const MetaType*> arguments,
                                   const MetaType* result, Invoker fn) {
  if (!fn) detail::throw_error("method '" + name + "' of run-time class '" + meta_->name() + "' has no body");
  // MetaInstance::call has checked that self is an instance of this class, hence a SimStateInstance.
  MetaMethod::Invoker call = [fn = std::move(fn)](Instance& self, std::span<const Value> args) {
    return fn(static_cast<SimStateInstance&>(self), args);
  };
  meta_->add_method(
      std::make_unique<MetaMethod>(std::move(name), result, std::move(arguments), std::move(call)));
  return *this;
}

ClassBuilder& ClassBuilder::alias(std::string old_name) {
  check_property_name(meta_->name(), old_name);
  if (meta_->own_props_.empty()) detail::throw_error("alias '" + old_name + "' given before any property");
  meta_->own_props_.back()->add_alias(std::move(old_name));
  return *this;
}

ClassBuilder& ClassBuilder::set_abstract(bool abstract) {
  meta_->abstract_ = abstract;
  return *this;
}

const MetaInstance& ClassBuilder::define(Registry& registry) {
  if (!meta_) detail::throw_error("ClassBuilder::define called twice");
  meta_->size_ = detail::align_up(meta_->size_, meta_->align_);
  meta_->finish();
  return registry.define(std::move(meta_));
}

const MetaInstance& ClassBuilder::define() { return define(Registry::global()); }

// ---- MetaProperty -----------------------------------------------------------------------------------------

void MetaProperty::set_value(SimStateInstance& obj, const Value& v) const {
  if (flags_.has(ReadOnly)) throw_read_only_named();
  if (!instance_fits(obj)) throw_owner(obj);
  if (v.type() == type_) {
    assign_raw(obj, v.data());
  } else {
    const Value converted = v.convert_to(*type_);
    assign_raw(obj, converted.data());
  }
}

bool MetaProperty::views_as(const MetaType& wanted) const noexcept {
  return type_->is_reference() && wanted.kind() == type_->kind() && wanted.target() != nullptr &&
         type_->target() != nullptr && type_->target()->is_a(*wanted.target());
}

bool MetaProperty::stores_from(const MetaType& given) const noexcept {
  return !flags_.has(ReadOnly) && type_->is_reference() && given.kind() == type_->kind() &&
         given.target() == type_->target();
}

void MetaProperty::throw_type(const MetaType& wanted) const {
  detail::throw_error("property '" + owner_->name() + "::" + name_ + "' holds " + type_->name() + ", not " +
                      wanted.name());
}

void MetaProperty::throw_read_only_named() const {
  detail::throw_error("property '" + owner_->name() + "::" + name_ + "' is read-only");
}

void MetaProperty::throw_set(const MetaType& given) const {
  if (flags_.has(ReadOnly)) throw_read_only_named();
  throw_type(given);
}

void MetaProperty::throw_owner(const SimStateInstance& obj) const {
  detail::throw_error("property '" + owner_->name() + "::" + name_ + "' does not belong to class '" +
                      obj.meta().name() + "'");
}

// ---- MetaMethod -------------------------------------------------------------------------------------------

std::string MetaMethod::signature() const {
  std::string s = name_ + "(";
  for (std::size_t i = 0; i < arguments_.size(); ++i) {
    if (i != 0) s += ", ";
    s += arguments_[i]->name();
  }
  s += ")";
  if (result_ != nullptr) s += " -> " + result_->name();
  return s;
}

Value MetaMethod::invoke(Instance& self, std::span<const Value> args) const {
  const std::string who = (owner_ != nullptr ? owner_->name() + "::" : std::string()) + name_;
  if (args.size() != arguments_.size())
    detail::throw_error(who + " takes " + std::to_string(arguments_.size()) + " argument(s), got " +
                        std::to_string(args.size()) + " (signature " + signature() + ")");
  bool exact = true;
  for (std::size_t i = 0; i < args.size(); ++i) exact = exact && args[i].type() == arguments_[i];
  if (exact) return invoker_(self, args);
  std::vector<Value> converted;
  converted.reserve(args.size());
  for (std::size_t i = 0; i < args.size(); ++i) {
    if (args[i].type() == arguments_[i]) {
      converted.push_back(args[i]);
      continue;
    }
    try {
      converted.push_back(args[i].convert_to(*arguments_[i]));
    } catch (const Error& e) {
      detail::throw_error(who + " argument " + std::to_string(i + 1) + ": " + e.what());
    }
  }
  return invoker_(self, converted);
}

// ---- Value ------------------------------------------------------------------------------------------------

void Value::throw_mismatch(const MetaType& wanted) const {
  detail::throw_error("value holds " + (type_ != nullptr ? type_->name() : std::string("nothing")) +
                      ", not " + wanted.name());
}

namespace {
// Reads a number of any arithmetic kind as a long double, exactly enough for the range checks below.
long double load_number(const MetaType& t, const void* p) {
  switch (t.kind()) {
    case TypeKind::Float:
      return *static_cast<const float*>(p);
    case TypeKind::Double:
      return *static_cast<const double*>(p);
    case TypeKind::UInt:
      return static_cast<long double>(static_cast<std::uint64_t>(t.load_integer(p)));
    default:
      return static_cast<long double>(t.load_integer(p));
  }
}
}  // namespace

Value Value::convert_to(const MetaType& target) const {
  if (type_ == &target) return *this;
  if (type_ == nullptr) detail::throw_error("expected " + target.name() + ", got nothing");
  if (type_->is_arithmetic() && target.is_arithmetic()) {
    const long double x = load_number(*type_, data());
    Value out(target);
    auto exact = [&](long double back) {
      if (!std::isnan(x) && back != x)
        detail::throw_error("expected " + target.name() + ", got " + type_->name() + " " + to_text() +
                            " which " + target.name() + " cannot hold exactly");
    };
    switch (target.kind()) {
      case TypeKind::Double: {
        const auto d = static_cast<double>(x);
        exact(d);
        *static_cast<double*>(out.data()) = d;
        return out;
      }
      case TypeKind::Float: {
        if (std::isfinite(x) &&
            (x > std::numeric_limits<float>::max() || x < std::numeric_limits<float>::lowest()))
          exact(std::numeric_limits<long double>::infinity());
        const auto f = static_cast<float>(x);
        exact(f);
        *static_cast<float*>(out.data()) = f;
        return out;
      }
      default: {
        const bool is_signed = target.kind() == TypeKind::Int;
        const int bits = static_cast<int>(target.size() * 8);
        const long double lo = is_signed ? -std::ldexp(1.0L, bits - 1) : 0.0L;
        const long double hi = is_signed ? std::ldexp(1.0L, bits - 1) - 1 : std::ldexp(1.0L, bits) - 1;
        if (std::isnan(x) || x != std::trunc(x) || x < lo || x > hi)
          detail::throw_error("expected " + target.name() + ", got " + type_->name() + " " + to_text() +
                              " which does not fit");
        if (is_signed) {
          target.store_integer(out.data(), static_cast<std::int64_t>(x));
        } else {
          target.store_integer(out.data(), static_cast<std::int64_t>(static_cast<std::uint64_t>(x)));
        }
        return out;
      }
    }
  }
  if (type_->is_reference() && target.is_reference() && type_->kind() == target.kind()) {
    // A reference (list) converts to another reference (list) type of the same kind when every target
    // fits the new target class: references to a base, or to a subclass when the instance is one.
    auto fits = [&](const SimStateInstance* t) {
      if (t != nullptr && target.target() != nullptr && !t->is_a(*target.target()))
        detail::throw_error("expected " + target.name() + ", got a reference to a '" + t->meta().name() +
                            "'");
    };
    if (type_->is_ref_list()) {
      const auto& src = *static_cast<const RefListBase*>(data());
      for (std::size_t i = 0; i < src.size(); ++i) fits(src.at(i));
    } else {
      fits(static_cast<const RefBase*>(data())->get());
    }
    Value out(target);
    target.assign(out.data(), data());  // both share the layout and the ops of their kind
    return out;
  }
  detail::throw_error("expected " + target.name() + ", got " + type_->name());
}

std::string Value::to_text() const {
  if (type_ == nullptr) return "<empty>";
  return type_->to_text(data());
}

Value Value::from_text(const MetaType& type, std::string_view text, const RefResolver* refs,
                       std::string_view origin) {
  Value v(type);
  type.from_text(v.data(), text, refs, origin);
  return v;
}

}  // namespace vsd
