// The fixture of the SOML++ tests that load one script into a fresh Environment with its own Registry
// and read what it prints, and error_of() for the text of the vsd::Error a call throws.
#pragma once

#include <gtest/gtest.h>

#include <functional>
#include <sstream>
#include <string>

#include "vsd/core.hpp"
#include "vsd/soml.hpp"

namespace soml_test {

/// The message of the vsd::Error @p fn throws, or "(no error)".
inline std::string error_of(const std::function<void()>& fn) {
  try {
    fn();
  } catch (const vsd::Error& e) {
    return e.what();
  }
  return "(no error)";
}

struct ScriptTest : ::testing::Test {
  vsd::Registry reg;
  vsd::Environment env{0, reg};
  std::ostringstream out;  // what the script prints
  vsd::soml::Module* soml = nullptr;
  void SetUp() override { soml = &env.use<vsd::soml::Module>(); }
  vsd::soml::Program& load(const std::string& text, const std::string& file = "test.soml") {
    vsd::soml::RunOptions o;
    o.out = &out;
    return soml->load(env.main_state(), file, text, o);
  }
};

}  // namespace soml_test
