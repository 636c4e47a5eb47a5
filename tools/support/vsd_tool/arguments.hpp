/** @file
 *  @brief Command-line arguments of the vsd-* tools: options declared up front, strict numbers.
 *
 *  One grammar for every tool: `--name VALUE` or `--name=VALUE` for options with a value, `--name` for
 *  flags, anything else is a positional argument (`-` alone is one: standard input), and `--` ends the
 *  options. An unknown option, a missing value, a repeated option that is not repeatable and a number that
 *  is not exactly a number in range are usage errors (UsageError: exit status 2).
 */
#pragma once

#include <cstdint>
#include <initializer_list>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace vsd::tool {

/// @brief The command line is wrong: the tool prints the message and "Try '<tool> --help'." and exits 2.
struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// @brief One option a command accepts.
struct Option {
  std::string_view name;      ///< with its dashes: "--dt"
  bool takes_value = false;   ///< `--dt 0.01`; else a flag (`--json`)
  bool repeatable = false;    ///< may be given more than once (values() has them all)
};

/// @brief Flag option @p name.
constexpr Option flag(std::string_view name) { return {name, false, false}; }
/// @brief Option @p name with a value (once).
constexpr Option with_value(std::string_view name) { return {name, true, false}; }
/// @brief Option @p name with a value, repeatable.
constexpr Option repeated(std::string_view name) { return {name, true, true}; }

/// @brief Parsed arguments of one command. @throws UsageError from the constructor.
class Arguments {
 public:
  Arguments(std::span<const std::string_view> args, std::initializer_list<Option> options);

  /// @brief True when option @p name was given.
  [[nodiscard]] bool has(std::string_view name) const;
  /// @brief The value of option @p name, if given.
  [[nodiscard]] std::optional<std::string_view> value(std::string_view name) const;
  /// @brief Every value of option @p name, in order.
  [[nodiscard]] std::vector<std::string_view> values(std::string_view name) const;
  [[nodiscard]] const std::vector<std::string_view>& positional() const noexcept { return positional_; }
  /// @brief Requires between @p min and @p max positional arguments; @p what names them in the message
  /// ("one FILE", "IN and OUT"). @throws UsageError
  void expect_positional(std::size_t min, std::size_t max, std::string_view what) const;

  /// @brief The value of @p name as a number in [@p min, @p max] (finite), or @p fallback when not given.
  [[nodiscard]] double real(std::string_view name, double fallback, double min, double max) const;
  /// @brief The value of @p name as an integer in [@p min, @p max], or @p fallback when not given.
  [[nodiscard]] std::int64_t integer(std::string_view name, std::int64_t fallback, std::int64_t min,
                                     std::int64_t max) const;
  [[nodiscard]] std::uint64_t unsigned_integer(std::string_view name, std::uint64_t fallback,
                                               std::uint64_t max) const;

 private:
  struct Given {
    std::string_view name;
    std::string_view value;
  };
  std::vector<Given> given_;
  std::vector<std::string_view> positional_;
};

/// @brief @p text as a finite number in [@p min, @p max]: the whole text, decimal or exponent form, no
/// spaces, no "inf"/"nan". @p what names it in the message ("--dt"). @throws UsageError
double parse_real(std::string_view text, std::string_view what, double min, double max);
/// @brief @p text as a decimal integer in [@p min, @p max] (no sign for unsigned). @throws UsageError
std::int64_t parse_integer(std::string_view text, std::string_view what, std::int64_t min, std::int64_t max);
std::uint64_t parse_unsigned(std::string_view text, std::string_view what, std::uint64_t max);
/// @brief Comma-separated finite numbers ("0.1,-2,3e-3"); every item must be one. @throws UsageError
std::vector<double> parse_reals(std::string_view text, std::string_view what);

/// @brief A number as the tools print it in messages: whole numbers below 10^15 as integers, others in the
/// shortest form that reads back exactly ("0.001", "1e+17").
std::string number_text(double v);

}  // namespace vsd::tool
