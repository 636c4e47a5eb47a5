#include "json.hpp"

#include <charconv>

#include "vsd/core/error.hpp"
#include "vsd/core/text.hpp"

namespace vsd::web::detail {

void JsonWriter::separate() {
  if (after_key_) {
    after_key_ = false;
    return;
  }
  if (!first_.empty()) {
    if (!first_.back()) out_ += ',';
    first_.back() = false;
  }
}

JsonWriter& JsonWriter::begin_object() {
  separate();
  out_ += '{';
  first_.push_back(true);
  return *this;
}
JsonWriter& JsonWriter::end_object() {
  out_ += '}';
  first_.pop_back();
  return *this;
}
JsonWriter& JsonWriter::begin_array() {
  separate();
  out_ += '[';
  first_.push_back(true);
  return *this;
}
JsonWriter& JsonWriter::end_array() {
  out_ += ']';
  first_.pop_back();
  return *this;
}
JsonWriter& JsonWriter::key(std::string_view k) {
  separate();
  write_quoted(out_, k);
  out_ += ':';
  after_key_ = true;
  return *this;
}
JsonWriter& JsonWriter::string(std::string_view s) {
  separate();
  write_quoted(out_, s);
  return *this;
}
JsonWriter& JsonWriter::number(double v) {
  separate();
  write_real(out_, v);  // NaN and the infinities as "nan", "inf", "-inf" (the value text form)
  return *this;
}
JsonWriter& JsonWriter::number(std::int64_t v) {
  separate();
  out_ += std::to_string(v);
  return *this;
}
JsonWriter& JsonWriter::number(std::uint64_t v) {
  separate();
  out_ += std::to_string(v);
  return *this;
}
JsonWriter& JsonWriter::boolean(bool v) {
  separate();
  out_ += v ? "true" : "false";
  return *this;
}
JsonWriter& JsonWriter::null() {
  separate();
  out_ += "null";
  return *this;
}
JsonWriter& JsonWriter::raw(std::string_view json) {
  separate();
  out_ += json;
  return *this;
}

JsonObject JsonObject::parse(std::string_view body) {
  JsonObject o;
  TextReader in(body, "request");
  if (in.peek() != '{') in.fail("expected a JSON object");
  in.expect('{');
  if (!in.accept('}')) {
    do {
      if (in.peek() != '"') in.fail("expected a quoted member name");
      std::string k = in.key();
      for (const auto& [name, text] : o.members_)
        if (name == k) in.fail("member \"" + k + "\" appears twice");
      in.expect(':');
      const std::size_t start = in.token_start();
      in.skip_value();  // nesting guarded: too deep a value throws
      o.members_.emplace_back(std::move(k), body.substr(start, in.position() - start));
    } while (in.accept(','));
    in.expect('}');
  }
  in.expect_end();
  return o;
}

const std::string_view* JsonObject::find(std::string_view name) const noexcept {
  for (const auto& [k, text] : members_)
    if (k == name) return &text;
  return nullptr;
}

std::string_view JsonObject::require(std::string_view name) const {
  if (const std::string_view* t = find(name)) return *t;
  throw Error("request: member \"" + std::string(name) + "\" is missing");
}

Id JsonObject::id(std::string_view name) const {
  std::string_view t = require(name);
  if (!t.empty() && t.front() == '"') {
    TextReader in(t, "request");
    return parse_id(in.string(), name);
  }
  return parse_id(t, name);
}

std::string JsonObject::string(std::string_view name) const {
  const std::string_view t = require(name);
  if (t.empty() || t.front() != '"')
    throw Error("request: member \"" + std::string(name) + "\" must be a string, not " + std::string(t));
  TextReader in(t, "request");
  return in.string();
}

bool JsonObject::boolean(std::string_view name) const {
  const std::string_view t = require(name);
  if (t == "true") return true;
  if (t == "false") return false;
  throw Error("request: member \"" + std::string(name) + "\" must be true or false, not " + std::string(t));
}

std::vector<std::string_view> JsonObject::array(std::string_view name) const {
  const std::string_view t = require(name);
  TextReader in(t, "request");
  if (in.peek() != '[') throw Error("request: member \"" + std::string(name) + "\" must be an array");
  std::vector<std::string_view> items;
  in.expect('[');
  if (!in.accept(']')) {
    do {
      const std::size_t start = in.token_start();
      in.skip_value();
      items.push_back(t.substr(start, in.position() - start));
    } while (in.accept(','));
    in.expect(']');
  }
  return items;
}

Id parse_id(std::string_view text, std::string_view what) {
  std::string_view digits = text;
  if (!digits.empty() && digits.front() == '@') digits.remove_prefix(1);
  Id id = 0;
  const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), id);
  if (digits.empty() || ec != std::errc{} || end != digits.data() + digits.size() || id == 0)
    throw Error("request: " + std::string(what) + " must be an instance id (a positive integer), not '" +
                std::string(text.substr(0, 64)) + "'");
  return id;
}

std::size_t parse_count(std::string_view text, std::string_view what, std::size_t max) {
  std::size_t n = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), n);
  if (text.empty() || end != text.data() + text.size() || (ec != std::errc{} && ec != std::errc::result_out_of_range))
    throw Error("request: " + std::string(what) + " must be a non-negative integer, not '" +
                std::string(text.substr(0, 64)) + "'");
  return ec == std::errc::result_out_of_range || n > max ? max : n;
}

}  // namespace vsd::web::detail
