// Golden scripts: every tests/soml/scripts/*.soml is parsed and checked; the diagnostics must be exactly
// those its `// expect error: line:col: message` (or `expect warning:`) comments list, and a script
// without such comments must check clean.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "vsd/soml/checker.hpp"

namespace {

namespace fs = std::filesystem;

std::vector<std::string> script_names() {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(VSD_SOML_SCRIPTS_DIR))
    if (e.path().extension() == ".soml") names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

std::string read(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// "error: 4:12: undefined name 'foo'" for each expectation comment of the text.
std::vector<std::string> expectations(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    for (const char* kind : {"error", "warning"}) {
      const std::string marker = std::string("// expect ") + kind + ": ";
      const auto at = line.find(marker);
      if (at != std::string::npos) out.push_back(std::string(kind) + ": " + line.substr(at + marker.size()));
    }
  }
  return out;
}

// One test runs every script (a script added to the directory is picked up without rebuilding or
// re-discovering tests); each mismatch names its script.
TEST(Scripts, EachReportsExactlyItsExpectedDiagnostics) {
  const auto names = script_names();
  ASSERT_FALSE(names.empty());
  for (const std::string& name : names) {
    SCOPED_TRACE(name);
    const std::string text = read(fs::path(VSD_SOML_SCRIPTS_DIR) / name);
    const auto result = vsd::soml::check_source(name, text);
    std::vector<std::string> actual;
    for (const auto& d : result->diagnostics.all()) {
      const char* kind = d.severity == vsd::soml::Severity::Error     ? "error"
                         : d.severity == vsd::soml::Severity::Warning ? "warning"
                                                                      : "note";
      actual.push_back(std::string(kind) + ": " + std::to_string(d.loc.line) + ":" +
                       std::to_string(d.loc.column) + ": " + d.message);
    }
    const std::vector<std::string> expected = expectations(text);
    EXPECT_EQ(actual, expected) << "full output:\n" << result->diagnostics.format();
    EXPECT_EQ(result->ok(), expected.empty());
  }
}

TEST(Scripts, CoverEveryErrorClassAndTheFeatures) {
  // The issue asks for at least one script per error class and clean scripts for the language.
  const auto names = script_names();
  for (const char* must :
       {"error_syntax.soml", "error_undefined.soml", "error_types.soml", "error_arrows.soml",
        "error_duplicates.soml", "error_arguments.soml", "features_classes.soml", "features_nets.soml",
        // run-time errors with their SOML++ call stacks (run goldens with `// expect-exit: 1`)
        "run_endless_loop.soml", "run_deep_recursion.soml", "run_division_by_zero.soml",
        "run_null_reference.soml", "run_index_range.soml"})
    EXPECT_NE(std::find(names.begin(), names.end(), must), names.end()) << must;
}

}  // namespace
