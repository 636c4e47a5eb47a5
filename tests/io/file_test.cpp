#include "vsd/io/file.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <random>
#include <thread>

#include "vsd/core/error.hpp"

namespace {

namespace fs = std::filesystem;

struct TempDir {
  fs::path path = fs::temp_directory_path() / ("vsd_file_test_" + std::to_string(::getpid()));
  TempDir() { fs::create_directories(path); }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
};

std::vector<std::uint8_t> pattern(std::size_t n, std::uint8_t seed) {
  std::vector<std::uint8_t> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = static_cast<std::uint8_t>(seed + i * 31);
  return v;
}

TEST(AtomicFile, WritesAndReplacesLeavingNoTemporaries) {
  TempDir dir;
  const fs::path file = dir.path / "model.bin";
  vsd::io::write_file_atomically(file, pattern(1000, 1));
  EXPECT_EQ(vsd::io::read_file(file), pattern(1000, 1));
  vsd::io::write_file_atomically(file, pattern(10, 2));
  EXPECT_EQ(vsd::io::read_file(file), pattern(10, 2));
  EXPECT_EQ(std::distance(fs::directory_iterator(dir.path), fs::directory_iterator()), 1);
}

TEST(AtomicFile, ErrorsNameTheFile) {
  TempDir dir;
  EXPECT_THAT([&] { vsd::io::write_file_atomically(dir.path / "missing" / "x.bin", pattern(4, 0)); },
              testing::ThrowsMessage<vsd::Error>(testing::HasSubstr("missing")));
  EXPECT_THAT([&] { (void)vsd::io::read_file(dir.path / "nope.bin"); },
              testing::ThrowsMessage<vsd::Error>(testing::HasSubstr("nope.bin: cannot open")));
  vsd::io::write_file_atomically(dir.path / "big.bin", pattern(100, 0));
  EXPECT_THAT([&] { (void)vsd::io::read_file(dir.path / "big.bin", 10); },
              testing::ThrowsMessage<vsd::Error>(testing::HasSubstr("exceeds the limit")));
}

// A child process saves large files over and over and is killed at a random moment: the file on disk
// must always be one complete version, never a torn one.
TEST(AtomicFile, AKilledSaveLeavesTheOldFileIntact) {
  TempDir dir;
  const fs::path file = dir.path / "model.bin";
  const auto a = pattern(4 << 20, 7);
  const auto b = pattern(3 << 20, 9);
  vsd::io::write_file_atomically(file, a);
  std::mt19937 rng(5);
  for (int round = 0; round < 6; ++round) {
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      for (int i = 0;; ++i) vsd::io::write_file_atomically(file, i % 2 == 0 ? b : a);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5 + rng() % 60));
    ::kill(child, SIGKILL);
    int status = 0;
    ::waitpid(child, &status, 0);
    const auto now = vsd::io::read_file(file);
    EXPECT_TRUE(now == a || now == b) << "round " << round << ": a torn file of " << now.size() << " bytes";
  }
}

}  // namespace
