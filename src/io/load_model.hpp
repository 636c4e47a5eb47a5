// Internal to vsd::io: what a loader reads from a file, whatever its format, and how that becomes one
// Transaction on the target state.
//
// A format's reader (binary: snapshot.cpp, text: text_snapshot.cpp) fills the model: the classes the
// file uses (defining the run-time ones it carries), every instance with its values already checked and
// in the binary form of the property's type, and references as the file's ids. finish() checks what
// spans instances (duplicate ids, dangling references, top-level nodes); apply() maps the ids and
// applies one bundle, which the SimState checks again before it changes anything.
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "vsd/core/detail/huge_pages.hpp"
#include "vsd/core/detail/id_map.hpp"
#include "vsd/io/snapshot.hpp"

namespace vsd::io::detail {

inline constexpr std::uint8_t kind_state = 0;
inline constexpr std::uint8_t kind_subtree = 1;

/// What persistence writes: Savable properties that are not Transient.
inline bool is_saved(const MetaProperty& p) { return p.has(Savable) && !p.has(Transient); }

/// One saved property of a class, as the file describes it.
struct Slot {
  const MetaProperty* prop = nullptr;  // null: the class has no such property any more
  const MetaType* file_type = nullptr;
  bool convert = false;  // a number whose type changed: converted value by value
};

struct ClassEntry {
  const MetaInstance* cls = nullptr;
  std::vector<Slot> slots;
};

// One value of a saved instance. 32 bytes: a load of a million instances holds several million of them,
// and every byte of them is fresh memory the kernel faults in (40 bytes each cost ~60 ms more per 1M).
struct SavedValue {
  const Slot* slot;
  const std::uint8_t* data = nullptr;  // the value in the property's type (binary form); not for references
  std::uint32_t size = 0;
  std::uint32_t delta = 0;      // its file position minus its instance's, for messages
  std::uint32_t ids_first = 0;  // reference targets (file ids): ids_[ids_first, + ids_count)
  std::uint32_t ids_count = 0;

  [[nodiscard]] std::span<const std::uint8_t> bytes() const noexcept { return {data, size}; }
};

struct SavedInstance {
  Id id;
  const ClassEntry* entry;
  std::size_t offset;
  std::size_t first;  // its values are values_[first, first + count)
  std::size_t count;
};

/// A run-time class definition as a file carries it.
struct ClassDefinition {
  std::string name;
  std::string base;
  bool abstract = false;
  struct Property {
    std::string name;
    const MetaType* type;
    PropertyFlags flags;
    Value default_value;
  };
  std::vector<Property> properties;
};

/// A saved property of a class as the file lists it (name, type name, where the type is written): what a
/// stand-in for a class the program does not know is made from (LoadOptions::unknown_classes).
struct SavedProperty {
  std::string_view name;
  std::string_view type;
  std::size_t at = 0;
};

/// A run-time value type (enum, flags or struct) as a file carries it.
struct TypeDefinition {
  std::string name;
  TypeKind kind = TypeKind::Enum;
  const MetaType* underlying = nullptr;  // enums and flags; null: the builder's default
  std::vector<MetaType::EnumValue> values;
  std::vector<std::pair<std::string, const MetaType*>> fields;  // structs
};

class LoadModel {
 public:
  LoadModel(Registry& registry, std::string_view origin, const LoadOptions& options = {})
      : registry_(registry), origin_(origin), options_(options) {}
  LoadModel(const LoadModel&) = delete;
  LoadModel& operator=(const LoadModel&) = delete;
  /// A load that did not commit leaves no class it defined behind.
  virtual ~LoadModel();

  /// Applies the model to @p state: under @p parent, or (nullptr) as the whole of an empty state.
  LoadReport apply(SimState& state, Node* parent);
  /// What a load would report, without loading (the classes the file defined are removed again).
  [[nodiscard]] LoadReport summary() const;

 protected:
  /// The origin and the position @p at in the format's terms ("file: byte 12", "file:3:14").
  [[nodiscard]] virtual std::string where(std::size_t at) const = 0;
  /// Where element @p k of the reference list whose value starts at @p value_at was written.
  [[nodiscard]] virtual std::size_t list_element_at(std::size_t value_at, std::size_t k) const = 0;
  /// Throws vsd::Error naming where(at) and @p what.
  [[noreturn]] void fail_at(std::size_t at, const std::string& what) const {
    throw Error(where(at) + ": " + what);
  }

  /// The type @p def describes: the program's own when it has one of that name and the same definition,
  /// else defined from @p def (removed again if the load fails). A type of that name that differs is an
  /// error at @p at.
  const MetaType& resolve_type(std::size_t at, const TypeDefinition& def);
  /// The class named @p name, defined from @p def when this program does not know it (def may be null).
  /// A class that neither the program nor the file defines is an error, or with
  /// UnknownClasses::Placeholder a stand-in made from its @p saved properties (make_placeholder()).
  const MetaInstance& resolve_class(std::size_t at, const std::string& name, const ClassDefinition* def,
                                    std::span<const SavedProperty> saved = {});
  /// How a saved property @p prop of type @p type_name (empty: unknown) of @p cls maps to today's class;
  /// schema differences are reported in warnings_.
  Slot make_slot(std::size_t at, const MetaInstance& cls, std::string_view prop, std::string_view type_name);
  const MetaType& type_named(std::size_t at, std::string_view name);

  /// A copy of @p bytes owned by the model (converted or parsed values) that never moves.
  std::span<const std::uint8_t> own(std::span<const std::uint8_t> bytes);

  /// Checks across instances once all are read: ids unique, top-level ids present and Nodes, every
  /// reference names an instance of the file.
  void finish();

  [[nodiscard]] std::span<const Id> ids_of(const SavedValue& v) const {
    return std::span<const Id>(ids_).subspan(v.ids_first, v.ids_count);
  }
  /// A value of property slot @p s at file position @p at of the instance at @p instance_at; its
  /// references are the ids that the reader appends to ids_ next.
  [[nodiscard]] SavedValue new_value(const Slot& s, std::size_t instance_at, std::size_t at) const {
    if (at - instance_at > UINT32_MAX) fail_at(at, "an instance cannot take more than 4 GiB of the file");
    return SavedValue{
        &s, nullptr, 0, static_cast<std::uint32_t>(at - instance_at), static_cast<std::uint32_t>(ids_.size()),
        0};
  }
  /// Sets the bytes of @p v (at most 4 GiB: a value's frame in a bundle is that big at most).
  void set_bytes(SavedValue& v, std::span<const std::uint8_t> bytes, std::size_t at) const {
    if (bytes.size() > UINT32_MAX) fail_at(at, "a value cannot take more than 4 GiB");
    v.data = bytes.data();
    v.size = static_cast<std::uint32_t>(bytes.size());
  }
  /// Keeps @p v unless it is a reference value without targets: the property then keeps its default (an
  /// empty list or null, as a new instance has), and most lists of a tree (a leaf's children) cost no value.
  void keep_value(SavedValue& v) {
    v.ids_count = static_cast<std::uint32_t>(ids_.size() - v.ids_first);
    if (v.slot->prop->type().is_reference() &&
        (v.ids_count == 0 || (v.ids_count == 1 && ids_[v.ids_first] == null_id))) {
      ids_.resize(v.ids_first);
      return;
    }
    values_.push_back(v);
  }
  [[nodiscard]] static std::size_t offset_of(const SavedInstance& x, const SavedValue& v) {
    return x.offset + v.delta;
  }
  [[nodiscard]] std::span<const SavedValue> values_of(const SavedInstance& x) const {
    return std::span<const SavedValue>(values_).subspan(x.first, x.count);
  }

  Registry& registry_;
  std::string_view origin_;
  LoadOptions options_;
  std::uint8_t kind_ = kind_state;
  int version_ = 1;
  std::deque<ClassEntry> classes_;  // a deque: entries never move while instances point at them
  // The big tables of a big file: in huge pages where the system gives them (huge_pages.hpp).
  template <class T>
  using BigVector = std::vector<T, vsd::detail::HugeAllocator<T>>;
  BigVector<SavedInstance> instances_;
  BigVector<SavedValue> values_;  // of all instances, in file order
  BigVector<Id> ids_;             // reference targets of all values
  // "top" as the file gives it: the subtree's roots, or a state's top-level nodes (checked against what
  // its Database holds). has_top_ is false for a text file without "top"; top_at_ is where it starts.
  std::vector<Id> top_;
  std::vector<std::size_t> top_offsets_;
  bool has_top_ = false;
  std::size_t top_at_ = 0;
  std::vector<std::string> warnings_;

 private:
  void check_composite_cycles() const;
  void check_one_parent() const;
  const MetaInstance& make_placeholder(std::size_t at, const std::string& name,
                                       std::span<const SavedProperty> saved);

  std::deque<std::vector<std::uint8_t>> arena_;  // chunks that are filled, never grown
  [[nodiscard]] const SavedInstance* find(Id id) const {
    const std::size_t i = by_id_.find(id);
    return i == 0 ? nullptr : &instances_[i - 1];
  }

  void check_top();

  vsd::detail::FlatIdMap<std::size_t> by_id_;  // id -> index in instances_ + 1 (0: none)
  const SavedInstance* file_root_ = nullptr;   // a state file's Database
  // The top-level nodes as finish() derived them: the Database's children in a state file that has one,
  // else "top". A load attaches them (or, as a whole state with a Database, restores them as its children).
  std::vector<Id> roots_;
  std::vector<const MetaInstance*> defined_;
  std::vector<const MetaInstance*> placeholders_;  // stand-ins (also in defined_, which removes them)
  std::vector<const MetaType*> defined_types_;
  bool committed_ = false;
};

}  // namespace vsd::io::detail
