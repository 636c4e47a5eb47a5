// Internal to vsd::io: what both formats' writers share, and the entry points of each format.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string_view>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "load_model.hpp"

namespace vsd::io::detail {

/// The instances a save writes, and the classes they use in an order that defines run-time bases first.
class SaveSet {
 public:
  SaveSet(std::vector<const SimStateInstance*> members, std::uint8_t kind, std::vector<Id> top,
          SaveReport* report);

  [[nodiscard]] const std::vector<const SimStateInstance*>& members() const noexcept { return members_; }
  [[nodiscard]] const std::vector<const MetaInstance*>& classes() const noexcept { return classes_; }
  [[nodiscard]] std::size_t class_index(const MetaInstance& c) const { return index_.at(&c); }
  /// The run-time value types (enums, flags, structs) the classes use, each after the types it holds:
  /// a file carries their definitions before the classes. Vectors of them are not listed (their names say
  /// what they are), nor are C++ types (the reading program has them).
  [[nodiscard]] const std::vector<const MetaType*>& types() const noexcept { return types_; }
  [[nodiscard]] std::uint8_t kind() const noexcept { return kind_; }
  [[nodiscard]] const std::vector<Id>& top() const noexcept { return top_; }

  /// The id a reference to @p t is written as: null for instances outside the set (counted as cut).
  Id member_id(const SimStateInstance* t);
  /// The ids reference property @p p of @p x is written as (a list leaves out targets outside the set).
  void reference_ids(const SimStateInstance& x, const MetaProperty& p, std::vector<Id>& out);

 private:
  void add_class(const MetaInstance& c);
  void add_type(const MetaType& t);

  std::vector<const SimStateInstance*> members_;
  std::unordered_set<const SimStateInstance*> member_set_;
  std::uint8_t kind_;
  std::vector<Id> top_;
  SaveReport* report_;
  std::vector<const MetaInstance*> classes_;
  std::unordered_map<const MetaInstance*, std::size_t> index_;
  std::vector<const MetaType*> types_;
  std::unordered_set<const MetaType*> type_set_;
};

/// The format version a writer writes: the first one (1) unless the file carries run-time types (2),
/// so that files without them stay readable by older programs.
inline int format_version_for(const SaveSet& set) { return set.types().empty() ? 1 : 2; }

std::vector<std::uint8_t> write_binary(SaveSet& set);
std::vector<std::uint8_t> write_text(SaveSet& set);

/// Reads and checks a file of the format into a model (then apply() it, or only look at it).
/// @p bytes must outlive the model: values point into them.
std::unique_ptr<LoadModel> read_binary(Registry& registry, std::span<const std::uint8_t> bytes,
                                       std::string_view origin, const LoadOptions& options = {});
std::unique_ptr<LoadModel> read_text(Registry& registry, std::span<const std::uint8_t> bytes,
                                     std::string_view origin, const LoadOptions& options = {});

}  // namespace vsd::io::detail
