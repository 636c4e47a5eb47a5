// How every tool ends: exit codes and messages for every kind of failure (tools/support/vsd_tool/runner.hpp).
#include "vsd_tool/runner.hpp"

#include <gtest/gtest.h>

#include <new>
#include <sstream>
#include <stdexcept>

#include "vsd/core/error.hpp"
#include "vsd_tool/arguments.hpp"

namespace vsd_tool_runner_test {
namespace {

using vsd::tool::Tool;

const Tool tool{"vsd-test", "Usage: vsd-test [--help]\n", true};

struct Outcome {
  int code;
  std::string out, err;
};

Outcome run(std::vector<std::string_view> args, const vsd::tool::Body& body) {
  std::ostringstream out, err;
  const int code = vsd::tool::run(tool, args, out, err, body);
  return {code, out.str(), err.str()};
}

Outcome throwing(const std::function<void()>& f) {
  return run({"x"}, [&](auto, std::ostream&, std::ostream&) -> int {
    f();
    return 0;
  });
}

TEST(ToolRunner, HelpAndExitCodes) {
  const auto never = [](auto, std::ostream&, std::ostream&) -> int { throw std::logic_error("not called"); };
  for (auto args : {std::vector<std::string_view>{"--help"}, {"a", "-h"}, {"help"}}) {
    const Outcome r = run(args, never);
    EXPECT_EQ(r.code, 0);
    EXPECT_EQ(r.out, "Usage: vsd-test [--help]\n");
  }
  EXPECT_EQ(run({"--", "--help"}, [](auto, std::ostream&, std::ostream&) { return 7; }).code, 7);
}

TEST(ToolRunner, EveryFailureIsAMessageAndAnExitCode) {
  Outcome r = throwing([] { throw vsd::tool::UsageError("--dt: 'abc' is not a number"); });
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "vsd-test: --dt: 'abc' is not a number\nTry 'vsd-test --help'.\n");
  r = throwing([] { throw vsd::Error("file.json:3:4: bad\n"); });
  EXPECT_EQ(r.code, 1);
  EXPECT_EQ(r.err, "vsd-test: file.json:3:4: bad\n");
  r = throwing([] { throw std::bad_alloc(); });
  EXPECT_EQ(r.code, 1);
  EXPECT_EQ(r.err, "vsd-test: out of memory\n");
  r = throwing([] { throw std::runtime_error("other"); });
  EXPECT_EQ(r.code, 1);
  EXPECT_EQ(r.err, "vsd-test: other\n");
  r = throwing([] { throw 42; });
  EXPECT_EQ(r.code, 1);
  EXPECT_EQ(r.err, "vsd-test: unexpected error\n");
  r = throwing([] { throw vsd::Error("name \x1b[31mred\x1b[0m\nsecond line"); });
  EXPECT_EQ(r.err, "vsd-test: name ?[31mred?[0m\nsecond line\n");
}

}  // namespace
}  // namespace vsd_tool_runner_test
