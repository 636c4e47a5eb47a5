// The fixture of the SOML++ tests that load one script into a fresh Environment with its own Registry
// and read what it prints, and error_of() (the core tests' helper) for the text of the vsd::Error a call
// throws.
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <sstream>
#include <string>

#include "../core/test_util.hpp"
#include "vsd/core.hpp"
#include "vsd/soml.hpp"

namespace soml_test {

using vsd_test::error_of;

// Each test has a registry of its own: script classes are defined into it. A fixture of a group of tests
// derives from this one to load its scripts under another name (`script_file`) or to add helpers.
struct ScriptTest : ::testing::Test {
  vsd::Registry reg;
  vsd::Environment env{0, reg};
  std::ostringstream out;  // what the script prints
  vsd::soml::Module* soml = nullptr;
  std::string script_file = "test.soml";  // the name load() gives a script when it is not told one
  void SetUp() override { soml = &env.use<vsd::soml::Module>(); }
  // Loads @p text as @p file into the main state, run with @p o (printing to `out`).
  vsd::soml::Program& load(const std::string& text, const std::string& file, vsd::soml::RunOptions o = {}) {
    o.out = &out;
    return soml->load(env.main_state(), file, text, o);
  }
  vsd::soml::Program& load(const std::string& text, vsd::soml::RunOptions o = {}) {
    return load(text, script_file, o);
  }
  // With the choice among enabled transitions seeded by @p seed.
  vsd::soml::Program& load(const std::string& text, std::uint64_t seed) {
    vsd::soml::RunOptions o;
    o.seed = seed;
    return load(text, o);
  }
};

}  // namespace soml_test
