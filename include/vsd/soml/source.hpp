/** @file
 *  @brief Source text of a SOML++ script and the diagnostics reported against it.
 *
 *  Every phase of the front end (lexer, parser, checker) reports problems into one `Diagnostics`
 *  list instead of throwing, so that all errors of a file come out together. A diagnostic knows its
 *  position (1-based line and byte column); `Diagnostics::format` renders each as
 *
 *      robot.soml:4:12: error: undefined name 'foo'
 *        x = foo + 1;
 *            ^
 *
 *  Lifetime: a `Source` owns its text; positions are offsets into it, so the AST and diagnostics of a
 *  script are only meaningful together with the Source they came from.
 */
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace vsd::soml {

/// @brief A position in a source text: byte offset, 1-based line and 1-based byte column.
struct SourceLoc {
  std::uint32_t offset = 0;
  std::uint32_t line = 1;
  std::uint32_t column = 1;
};

/// @brief The largest SOML++ script, in bytes: 256 MiB (the 10,000-line benchmark script is 0.3 MB).
/// A longer text is refused with one error at 1:1 (positions are 32-bit); the vsd-* tools read a file
/// they know to be a script up to this size and no further.
inline constexpr std::size_t max_source_bytes = std::size_t{1} << 28;

/// @brief A named source text with a line table.
class Source {
 public:
  /// @brief Takes the script text @p text, shown in diagnostics as @p name (usually the file path).
  /// A text longer than max_source_bytes is cut there (too_long() says so; check_source reports it).
  Source(std::string name, std::string text);

  [[nodiscard]] const std::string& name() const noexcept { return name_; }
  [[nodiscard]] const std::string& text() const noexcept { return text_; }
  /// @brief Line and column of byte @p offset (clamped to the end of the text).
  [[nodiscard]] SourceLoc locate(std::size_t offset) const noexcept;
  /// @brief The text of 1-based line @p line without its line break (empty when out of range).
  [[nodiscard]] std::string_view line_text(std::uint32_t line) const noexcept;
  [[nodiscard]] std::size_t line_count() const noexcept { return line_starts_.size(); }
  /// @brief The size of the text given, when it was longer than max_source_bytes; else 0.
  [[nodiscard]] std::size_t too_long() const noexcept { return too_long_; }

 private:
  std::string name_;
  std::string text_;
  std::size_t too_long_ = 0;
  std::vector<std::uint32_t> line_starts_;
};

/// @brief How bad a diagnostic is.
enum class Severity : unsigned char { Error, Warning, Note };

/// @brief One problem found in a script.
struct Diagnostic {
  Severity severity = Severity::Error;
  SourceLoc loc;
  std::string message;
};

/// @brief The diagnostics of one source, in the order they were reported.
class Diagnostics {
 public:
  /// @brief Collects diagnostics about @p source (which must outlive this list).
  explicit Diagnostics(const Source& source) : source_(&source) {}

  /// @brief Reports an error at @p loc.
  void error(SourceLoc loc, std::string message);
  /// @brief Reports a warning at @p loc.
  void warning(SourceLoc loc, std::string message);
  /// @brief Reports a note at @p loc (context for the diagnostic before it).
  void note(SourceLoc loc, std::string message);

  [[nodiscard]] const std::vector<Diagnostic>& all() const noexcept { return list_; }
  [[nodiscard]] std::size_t error_count() const noexcept { return errors_; }
  [[nodiscard]] bool has_errors() const noexcept { return errors_ != 0; }
  [[nodiscard]] bool empty() const noexcept { return list_.empty(); }
  [[nodiscard]] const Source& source() const noexcept { return *source_; }

  /// @brief Orders the diagnostics by position (stable: those at one position keep their order).
  void sort();

  /// @brief One diagnostic as "file:line:col: error: message", the source line and a caret line.
  [[nodiscard]] std::string format(const Diagnostic& d) const;
  /// @brief All diagnostics, formatted and joined.
  [[nodiscard]] std::string format() const;

  /// @brief At most this many diagnostics are kept (a garbage file must not produce megabytes);
  /// the last one kept says that more were dropped.
  static constexpr std::size_t max_diagnostics = 200;

 private:
  void add(Severity s, SourceLoc loc, std::string message);
  const Source* source_;
  std::vector<Diagnostic> list_;
  std::size_t errors_ = 0;
  bool truncated_ = false;
};

}  // namespace vsd::soml
