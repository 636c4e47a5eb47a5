// Test helpers: the whole database and a firing as text with instances named by their paths in the tree
// (ids of instances made in another Environment may differ, names and places in the tree do not). Used by
// the tests that compare two runs (attach_test.cpp, native_test.cpp).
#pragma once

#include <cctype>
#include <initializer_list>
#include <string>
#include <string_view>

#include "vsd/core.hpp"
#include "vsd/soml.hpp"

namespace vsd_test {

// Where a node is in the tree, by names: ids of instances made after a reload may differ from the
// original's (each Environment counts its own), names and places in the tree do not.
inline std::string path(const vsd::SimStateInstance* x) {
  if (x == nullptr) return "-";
  const vsd::Node* n = x->as<vsd::Node>();
  if (n == nullptr) return "#?";
  std::string s;
  for (; n != nullptr && n->parent() != nullptr; n = n->parent()) s = "/" + n->name() + s;
  return s.empty() ? "/" : s;
}

// The text of a value with every "@id" replaced by the path of that instance.
inline std::string with_paths(const vsd::SimState& state, const std::string& text) {
  std::string out;
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (text[i] != '@' || i + 1 >= text.size() ||
        std::isdigit(static_cast<unsigned char>(text[i + 1])) == 0) {
      out += text[i];
      continue;
    }
    std::size_t j = i + 1;
    while (j < text.size() && std::isdigit(static_cast<unsigned char>(text[j])) != 0) ++j;
    out += path(state.find(std::stoull(text.substr(i + 1, j - i - 1))));
    i = j - 1;
  }
  return out;
}

// The whole tree: every node's class and every property (references as paths), depth first.
// (@p skip: nodes of classes left out, by name)
inline std::string dump(const vsd::SimState& state, std::initializer_list<std::string_view> skip = {}) {
  std::string s;
  state.database().visit([&](const vsd::Node& n) {
    for (std::string_view c : skip)
      if (n.meta().name() == c) return;
    s += path(&n) + " " + n.meta().name() + " {";
    for (const vsd::MetaProperty* p : n.meta().properties()) {
      if (p->name() == "children") continue;
      s += " " + p->name() + "=" + with_paths(state, p->type().to_text(p->address(n)));
    }
    s += " }\n";
  });
  return s;
}

inline std::string describe(const vsd::SimState& state, const vsd::soml::Firing& f) {
  static const char* kinds[] = {"plain", "invoke", "finish", "complete"};
  std::string s = std::to_string(f.step) + " " + kinds[static_cast<int>(f.kind)] + " " + path(f.transition) +
                  " mark " + path(f.mark != 0 ? state.find(f.mark) : nullptr) + " " + path(f.from) + " -> " +
                  path(f.to);
  for (const auto& m : f.taken) s += " -" + std::to_string(m.count) + path(m.place);
  for (const auto& m : f.given) s += " +" + std::to_string(m.count) + path(m.place);
  return s;
}

}  // namespace vsd_test
