/** @file
 *  @brief Save a SimState (or one subtree) and load it into an empty state or under a node of an existing
 *  one, as a readable text file or a compact binary snapshot.
 *
 *  What is written is decided by the meta-information: every Savable, non-Transient property of every
 *  instance, references by id, and the definitions of the run-time classes and run-time value types
 *  (EnumBuilder, StructBuilder) the instances use (so a program that never defined them can load the
 *  file, inspect it and save it again unchanged). Classes are named by their full names ("scene::Hull").
 *
 *  Two formats, one API; a load recognises the format by the file's first bytes. Each has versions 1 and
 *  2 (2 adds the run-time types); a save writes 2 only when the file carries run-time types:
 *  - Format::Text, "vsd-text": JSON (RFC 8259), one instance per object and one property per line so
 *    that it diffs well; each value is its type's text form (MetaType::write_text). Errors say line:col.
 *    See docs/file-formats.md.
 *  - Format::Binary, "VSDS": a type table (version 2), a class table (name, run-time definition if any,
 *    the saved properties by name and type name), then the instances (id, class, one length-framed value
 *    per saved property in each property type's binary form), then the top-level node ids. Errors say
 *    the byte offset.
 *
 *  Loading is all or nothing: the file is read and checked into a Transaction bundle, which the target
 *  SimState checks again (ids, classes, values, reference targets, list positions, composite cycles)
 *  before it changes anything. A malformed, truncated or hostile file gets a vsd::Error with the position
 *  and what was wrong; the target state is exactly as before. Schema evolution: a property the class no
 *  longer has is reported (LoadReport::warnings) and dropped; one the file lacks keeps its default; a
 *  renamed one is found through the class's aliases (ClassBuilder::alias, MetaProperty::add_alias); a value
 *  whose type changed converts when the number fits, and is reported otherwise.
 */
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "vsd/core.hpp"

namespace vsd::io {

/// @brief The two file formats.
enum class Format : std::uint8_t {
  Binary,  ///< "VSDS" snapshot: compact and fast
  Text     ///< "vsd-text" JSON: readable, diffs well in version control
};

/// @brief The format a file name asks for: Text for ".json" (any case), Binary otherwise.
Format format_for(const std::filesystem::path& path);
/// @brief The format of a file's content (by its first bytes). @throws vsd::Error when it is neither.
Format format_of(std::span<const std::uint8_t> bytes, std::string_view origin = "file");

/// @brief What a load does with a class that neither this program nor the file defines (an instance of a
/// C++ class of another program, say).
enum class UnknownClasses : std::uint8_t {
  Refuse,      ///< the load fails with an error naming the class (the default)
  /// A stand-in run-time class of that name is defined from what the file says: its base is the class of
  /// this program whose saved properties the file lists first, with the same names, types and order (as a
  /// save writes them, bases first: Node, say; vsd's core classes before a module's, the Database never),
  /// its own properties are the other saved ones. References to classes nobody knows become references
  /// to any instance; a property of a value type this program does not know is left out. The instances
  /// load with their saved values, LoadReport::placeholder_classes names the stand-ins and a warning each
  /// says what was made. A text file needs its "classes" table for this (it names the saved types).
  Placeholder
};

/// @brief How a load treats what this program does not know.
struct LoadOptions {
  UnknownClasses unknown_classes = UnknownClasses::Refuse;
};

/// @brief What a save wrote.
struct SaveReport {
  std::size_t instances = 0;
  /// References to instances outside a saved subtree; they are written as null.
  std::size_t cut_references = 0;
};

/// @brief What a load did.
struct LoadReport {
  /// The format the file was in, and whether it held a subtree (else a whole state).
  Format format = Format::Binary;
  bool subtree = false;
  std::size_t instances = 0;
  /// The format version of the file.
  int version = 1;
  /// The nodes that were top level in the file, now attached to the target: the Database's children in a
  /// state file (its "top" must list the same nodes), or the nodes "top" names in a subtree file or in a
  /// state file without a Database.
  std::vector<Node*> roots;
  /// Run-time classes the file defined that this program did not know.
  std::vector<std::string> defined_classes;
  /// Run-time value types (enums, flags, structs) the file defined that this program did not know.
  std::vector<std::string> defined_types;
  /// Stand-ins made for classes neither this program nor the file defined (UnknownClasses::Placeholder).
  std::vector<std::string> placeholder_classes;
  /// Schema differences found and handled: unknown properties, changed types.
  std::vector<std::string> warnings;
};

/// @brief The whole state in @p format.
std::vector<std::uint8_t> save_bytes(const SimState& state, Format format = Format::Binary,
                                     SaveReport* report = nullptr);
/// @brief @p root and everything it holds compositely (children, extensions, composite references).
std::vector<std::uint8_t> save_bytes(const Node& root, Format format = Format::Binary,
                                     SaveReport* report = nullptr);

/// @brief Loads a whole-state file (either format) into @p state, which must be empty; ids are kept.
LoadReport load_bytes(SimState& state, std::span<const std::uint8_t> bytes,
                      std::string_view origin = "snapshot");
/// @brief Loads a file (either format) under @p parent; instances get fresh ids of @p parent's Environment.
/// The file's Database stands for @p parent: its children become @p parent's, references to it point at
/// @p parent, and its own values are not copied.
LoadReport load_bytes(Node& parent, std::span<const std::uint8_t> bytes,
                      std::string_view origin = "snapshot");
/// @brief load_bytes() with @p options (what to do with classes nobody defines).
LoadReport load_bytes(SimState& state, std::span<const std::uint8_t> bytes, std::string_view origin,
                      const LoadOptions& options);
LoadReport load_bytes(Node& parent, std::span<const std::uint8_t> bytes, std::string_view origin,
                      const LoadOptions& options);

/// @brief Reads and checks a file (either format) as a load would, without loading it: what a load
/// would report (LoadReport::roots stays empty). Run-time classes the file defines are defined while it
/// is checked and removed again. @throws vsd::Error as a load would.
LoadReport check_bytes(std::span<const std::uint8_t> bytes, std::string_view origin = "file",
                       Registry& registry = Registry::global(), const LoadOptions& options = {});

/// @brief save_bytes() written with write_file_atomically(), in the format the file name asks for.
SaveReport save(const SimState& state, const std::filesystem::path& path);
SaveReport save(const Node& root, const std::filesystem::path& path);
SaveReport save(const SimState& state, const std::filesystem::path& path, Format format);
SaveReport save(const Node& root, const std::filesystem::path& path, Format format);
/// @brief load_bytes() of a file; errors name the file.
LoadReport load(SimState& state, const std::filesystem::path& path);
LoadReport load(Node& parent, const std::filesystem::path& path);
LoadReport load(SimState& state, const std::filesystem::path& path, const LoadOptions& options);
LoadReport load(Node& parent, const std::filesystem::path& path, const LoadOptions& options);

}  // namespace vsd::io
