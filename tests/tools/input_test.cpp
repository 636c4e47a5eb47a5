// Reading the tools' inputs and writing their outputs (tools/support/vsd_tool/input.hpp).
#include "vsd_tool/input.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <sstream>
#include <thread>

#include "tool_run.hpp"
#include "vsd/core/error.hpp"

namespace vsd_tool_input_test {
namespace {

using testing::HasSubstr;
using vsd::tool::read_input;
using vsd::tool::read_text_input;
using vsd::tool::write_output;
using vsd_tool_test::TempDir;

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const vsd::Error& e) {
    return e.what();
  }
  return "";
}

TEST(ToolInput, ReadsFilesPipesFifosAndStandardInput) {
  const TempDir tmp("vsd_tool_input");
  EXPECT_EQ(read_text_input(tmp.write("a.txt", "hello")), "hello");
  EXPECT_EQ(read_text_input(tmp.write("empty.txt", "")), "");
  // A FIFO is read as a stream, to its end (more than one chunk).
  const std::string fifo = tmp.path("fifo");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const std::string big(200'000, 'x');
  std::thread writer([&] { std::ofstream(fifo) << big; });
  EXPECT_EQ(read_text_input(fifo), big);
  writer.join();
  // "-" is standard input (a pipe here).
  int fds[2];
  ASSERT_EQ(::pipe(fds), 0);
  const int saved = ::dup(0);
  ::dup2(fds[0], 0);
  ::close(fds[0]);
  ASSERT_EQ(::write(fds[1], "from stdin", 10), 10);
  ::close(fds[1]);
  const std::string text = read_text_input("-");
  ::dup2(saved, 0);
  ::close(saved);
  EXPECT_EQ(text, "from stdin");
  EXPECT_EQ(vsd::tool::input_name("-"), "standard input");
}

TEST(ToolInput, SaysWhatIsWrong) {
  const TempDir tmp("vsd_tool_input_errors");
  EXPECT_EQ(error_of([&] { read_input(tmp.dir().string()); }), tmp.dir().string() + ": is a directory");
  EXPECT_THAT(error_of([&] { read_input(tmp.path("missing")); }),
              HasSubstr("missing: cannot open: No such file or directory"));
  EXPECT_THAT(error_of([&] { read_input(tmp.write("big", std::string(100, 'x')), 99); }),
              HasSubstr("big: is larger than 99 bytes"));
  const vsd_tool_test::IgnoreSigpipe no_sigpipe;
  int fds[2];
  ASSERT_EQ(::pipe(fds), 0);
  const int saved = ::dup(0);
  ::dup2(fds[0], 0);
  ::close(fds[0]);
  std::thread writer([fd = fds[1]] {
    const std::string chunk(4096, 'y');
    for (int i = 0; i < 64; ++i)
      if (::write(fd, chunk.data(), chunk.size()) < 0) break;  // stops when the reader gave up
    ::close(fd);
  });
  const std::string e = error_of([&] { read_input("-", 10'000); });
  ::dup2(saved, 0);  // the writer sees a closed pipe
  ::close(saved);
  writer.join();
  EXPECT_EQ(e, "standard input: is larger than 10000 bytes");
  // A name with control characters is not echoed raw.
  EXPECT_THAT(error_of([&] { read_input(tmp.path("no\x1b[2Jsuch")); }), HasSubstr("no?[2Jsuch: cannot open"));
}

TEST(ToolInput, WritesAtomicallyOrToStandardOutput) {
  const TempDir tmp("vsd_tool_output");
  std::ostringstream out;
  const std::string file = tmp.write("f.txt", "old");
  write_output(file, std::string_view("new"), out);
  EXPECT_EQ(TempDir::read(file), "new");
  write_output("-", std::string_view("to stdout"), out);
  EXPECT_EQ(out.str(), "to stdout");
  {
    const vsd_tool_test::FileSizeLimit full(4);
    EXPECT_THROW(write_output(file, std::string_view("much too long"), out), vsd::Error);
  }
  EXPECT_EQ(TempDir::read(file), "new") << "a failed write leaves the old file whole";
  EXPECT_THROW(write_output(tmp.path("no/such/dir/f"), std::string_view("x"), out), vsd::Error);
}

TEST(ToolInput, KindsOfInput) {
  using vsd::tool::has_extension;
  using vsd::tool::looks_like_xml;
  EXPECT_TRUE(has_extension("robot.URDF", ".urdf"));
  EXPECT_FALSE(has_extension("urdf", ".urdf"));
  const auto bytes = [](std::string_view s) { return std::vector<std::uint8_t>(s.begin(), s.end()); };
  EXPECT_TRUE(looks_like_xml(bytes("  \n<robot/>")));
  EXPECT_TRUE(looks_like_xml(bytes("\xEF\xBB\xBF<?xml?>")));
  EXPECT_FALSE(looks_like_xml(bytes("{\"format\": 1}")));
  EXPECT_FALSE(looks_like_xml(bytes("")));
}

}  // namespace
}  // namespace vsd_tool_input_test
