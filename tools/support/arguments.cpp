// Command-line arguments and strict numbers for the vsd-* tools (see vsd_tool/arguments.hpp).
#include "vsd_tool/arguments.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>

#include "vsd_tool/text.hpp"

namespace vsd::tool {

namespace {

std::string quoted(std::string_view s) { return "'" + printable(s) + "'"; }

const Option* find(std::initializer_list<Option> options, std::string_view name) {
  for (const Option& o : options)
    if (o.name == name) return &o;
  return nullptr;
}

}  // namespace

Arguments::Arguments(std::span<const std::string_view> args, std::initializer_list<Option> options) {
  bool options_end = false;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string_view a = args[i];
    if (options_end || a.size() < 2 || a[0] != '-') {
      positional_.push_back(a);
      continue;
    }
    if (a == "--") {
      options_end = true;
      continue;
    }
    const std::size_t eq = a.find('=');
    const std::string_view name = a.substr(0, eq);
    const Option* o = find(options, name);
    if (o == nullptr) throw UsageError("unknown option " + quoted(name));
    if (!o->repeatable && has(name)) throw UsageError(std::string(name) + " is given twice");
    if (!o->takes_value) {
      if (eq != std::string_view::npos) throw UsageError(std::string(name) + " takes no value");
      given_.push_back({name, {}});
    } else if (eq != std::string_view::npos) {
      given_.push_back({name, a.substr(eq + 1)});
    } else {
      if (i + 1 >= args.size()) throw UsageError(std::string(name) + " needs a value");
      given_.push_back({name, args[++i]});
    }
  }
}

bool Arguments::has(std::string_view name) const {
  return std::any_of(given_.begin(), given_.end(), [&](const Given& g) { return g.name == name; });
}

std::optional<std::string_view> Arguments::value(std::string_view name) const {
  std::optional<std::string_view> v;
  for (const Given& g : given_)
    if (g.name == name) v = g.value;
  return v;
}

std::vector<std::string_view> Arguments::values(std::string_view name) const {
  std::vector<std::string_view> out;
  for (const Given& g : given_)
    if (g.name == name) out.push_back(g.value);
  return out;
}

void Arguments::expect_positional(std::size_t min, std::size_t max, std::string_view what) const {
  if (positional_.size() < min) throw UsageError("needs " + std::string(what));
  if (positional_.size() > max)
    throw UsageError("takes " + std::string(what) + "; " + quoted(positional_[max]) + " is one too many");
}

double Arguments::real(std::string_view name, double fallback, double min, double max) const {
  const auto v = value(name);
  return v ? parse_real(*v, name, min, max) : fallback;
}

std::int64_t Arguments::integer(std::string_view name, std::int64_t fallback, std::int64_t min,
                                std::int64_t max) const {
  const auto v = value(name);
  return v ? parse_integer(*v, name, min, max) : fallback;
}

std::uint64_t Arguments::unsigned_integer(std::string_view name, std::uint64_t fallback,
                                          std::uint64_t max) const {
  const auto v = value(name);
  return v ? parse_unsigned(*v, name, max) : fallback;
}

double parse_real(std::string_view text, std::string_view what, double min, double max) {
  double v = 0;
  // from_chars: no leading spaces or '+', no hex without a flag; inf and nan are refused below.
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (text.empty() || ec == std::errc::invalid_argument || end != text.data() + text.size() ||
      !std::isfinite(v))
    throw UsageError(std::string(what) + ": " + quoted(text) + " is not a number");
  if (ec == std::errc::result_out_of_range || v < min || v > max)
    throw UsageError(std::string(what) + ": " + quoted(text) + " is out of range (" + number_text(min) +
                     " to " + number_text(max) + ")");
  return v;
}

std::int64_t parse_integer(std::string_view text, std::string_view what, std::int64_t min, std::int64_t max) {
  std::int64_t v = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (text.empty() || ec == std::errc::invalid_argument || end != text.data() + text.size())
    throw UsageError(std::string(what) + ": " + quoted(text) + " is not an integer");
  if (ec == std::errc::result_out_of_range || v < min || v > max)
    throw UsageError(std::string(what) + ": " + quoted(text) + " is out of range (" + std::to_string(min) +
                     " to " + std::to_string(max) + ")");
  return v;
}

std::uint64_t parse_unsigned(std::string_view text, std::string_view what, std::uint64_t max) {
  std::uint64_t v = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (text.empty() || ec == std::errc::invalid_argument || end != text.data() + text.size())
    throw UsageError(std::string(what) + ": " + quoted(text) + " is not a non-negative integer");
  if (ec == std::errc::result_out_of_range || v > max)
    throw UsageError(std::string(what) + ": " + quoted(text) + " is out of range (0 to " +
                     std::to_string(max) + ")");
  return v;
}

std::vector<double> parse_reals(std::string_view text, std::string_view what) {
  std::vector<double> out;
  std::size_t pos = 0;
  while (true) {
    const std::size_t comma = std::min(text.find(',', pos), text.size());
    const std::string_view item = text.substr(pos, comma - pos);
    double v = 0;
    const auto [end, ec] = std::from_chars(item.data(), item.data() + item.size(), v);
    if (item.empty() || ec != std::errc() || end != item.data() + item.size() || !std::isfinite(v))
      throw UsageError(std::string(what) + ": " + quoted(item) + " is not a number");
    out.push_back(v);
    if (comma == text.size()) break;
    pos = comma + 1;
  }
  return out;
}

std::string number_text(double v) {
  if (v == 0.0) v = 0.0;  // no "-0"
  if (std::abs(v) < 1e15 && v == std::floor(v)) return std::to_string(static_cast<std::int64_t>(v));
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);  // the shortest text that reads back exactly
  return std::string(buf, r.ptr);
}

}  // namespace vsd::tool
