// Source text, line table and diagnostics of SOML++ scripts.
#include "vsd/soml/source.hpp"

#include <algorithm>

namespace vsd::soml {

Source::Source(std::string name, std::string text) : name_(std::move(name)), text_(std::move(text)) {
  if (text_.size() > max_source_bytes) {  // positions are 32-bit: keep what they can name, for the message
    too_long_ = text_.size();
    text_.resize(max_source_bytes);
    text_.shrink_to_fit();
  }
  line_starts_.push_back(0);
  for (std::size_t i = 0; i < text_.size(); ++i)
    if (text_[i] == '\n') line_starts_.push_back(static_cast<std::uint32_t>(i + 1));
}

SourceLoc Source::locate(std::size_t offset) const noexcept {
  offset = std::min(offset, text_.size());
  // The last line start at or before offset.
  auto it = std::upper_bound(line_starts_.begin(), line_starts_.end(), static_cast<std::uint32_t>(offset));
  const auto line = static_cast<std::uint32_t>(it - line_starts_.begin());
  return {static_cast<std::uint32_t>(offset), line,
          static_cast<std::uint32_t>(offset - line_starts_[line - 1] + 1)};
}

std::string_view Source::line_text(std::uint32_t line) const noexcept {
  if (line == 0 || line > line_starts_.size()) return {};
  const std::size_t begin = line_starts_[line - 1];
  std::size_t end = line < line_starts_.size() ? line_starts_[line] - 1 : text_.size();
  if (end > begin && text_[end - 1] == '\r') --end;
  return std::string_view(text_).substr(begin, end - begin);
}

void Diagnostics::add(Severity s, SourceLoc loc, std::string message) {
  if (s == Severity::Error) ++errors_;
  if (truncated_) return;
  if (list_.size() + 1 >= max_diagnostics) {
    truncated_ = true;
    list_.push_back({Severity::Error, loc, "too many errors; the rest of the file is not reported"});
    return;
  }
  list_.push_back({s, loc, std::move(message)});
}

void Diagnostics::error(SourceLoc loc, std::string message) { add(Severity::Error, loc, std::move(message)); }
void Diagnostics::warning(SourceLoc loc, std::string message) {
  add(Severity::Warning, loc, std::move(message));
}
void Diagnostics::note(SourceLoc loc, std::string message) { add(Severity::Note, loc, std::move(message)); }

void Diagnostics::sort() {
  // The "too many errors" marker stays last.
  const auto end = truncated_ ? list_.end() - 1 : list_.end();
  std::stable_sort(list_.begin(), end,
                   [](const Diagnostic& a, const Diagnostic& b) { return a.loc.offset < b.loc.offset; });
}

namespace {
// Bytes that would garble a terminal (control characters, NUL) are shown as '?'; the caret line keeps
// tabs so that it lines up under the source line.
void append_printable(std::string& out, std::string_view s) {
  for (char c : s) {
    const auto u = static_cast<unsigned char>(c);
    out += (u < 0x20 && c != '\t') || u == 0x7f ? '?' : c;
  }
}
}  // namespace

std::string Diagnostics::format(const Diagnostic& d) const {
  static constexpr std::string_view kinds[] = {"error", "warning", "note"};
  std::string out = source_->name();
  out += ':';
  out += std::to_string(d.loc.line);
  out += ':';
  out += std::to_string(d.loc.column);
  out += ": ";
  out += kinds[static_cast<int>(d.severity)];
  out += ": ";
  append_printable(out, d.message);
  out += '\n';
  std::string_view line = source_->line_text(d.loc.line);
  std::size_t caret = std::min<std::size_t>(d.loc.column - 1, line.size());
  // A very long line (generated code, a minified file) is shown as a window around the column.
  constexpr std::size_t window = 120;
  const bool cut_front = caret > window / 2 && line.size() > window;
  if (cut_front) {
    const std::size_t from = std::min(caret - window / 2, line.size() - window / 2);
    line.remove_prefix(from);
    caret -= from;
  }
  const bool cut_back = line.size() > window;
  if (cut_back) line = line.substr(0, window);
  out += cut_front ? "  ..." : "  ";
  append_printable(out, line);
  out += cut_back ? "...\n  " : "\n  ";
  if (cut_front) out += "   ";
  for (std::size_t i = 0; i < caret && i < line.size(); ++i) out += line[i] == '\t' ? '\t' : ' ';
  out += "^\n";
  return out;
}

std::string Diagnostics::format() const {
  std::string out;
  for (const Diagnostic& d : list_) out += format(d);
  return out;
}

}  // namespace vsd::soml
