#include "vsd/io/file.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/mount.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <new>
#include <random>
#include <thread>

#include "../core/memory_cap.hpp"
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

using testing::HasSubstr;
using testing::ThrowsMessage;

mode_t mode_of(const fs::path& p) {
  struct stat st {};
  EXPECT_EQ(::lstat(p.c_str(), &st), 0) << p;
  return st.st_mode;
}

std::size_t entries(const fs::path& dir) {
  return static_cast<std::size_t>(std::distance(fs::directory_iterator(dir), fs::directory_iterator()));
}

TEST(AtomicFile, WritesThroughSymbolicLinks) {
  TempDir dir;
  fs::create_directories(dir.path / "data");
  const fs::path file = dir.path / "data" / "model.bin";
  vsd::io::write_file_atomically(file, pattern(10, 1));
  fs::create_symlink("data/model.bin", dir.path / "link");    // relative: against the link's directory
  fs::create_symlink(dir.path / "link", dir.path / "link2");  // a chain of two
  vsd::io::write_file_atomically(dir.path / "link2", pattern(20, 2));
  EXPECT_TRUE(fs::is_symlink(dir.path / "link2")) << "the link stays a link";
  EXPECT_TRUE(fs::is_symlink(dir.path / "link"));
  EXPECT_EQ(vsd::io::read_file(file), pattern(20, 2)) << "the target has the new contents";
  // A dangling link: the file it names is made.
  fs::create_symlink("data/new.bin", dir.path / "dangling");
  vsd::io::write_file_atomically(dir.path / "dangling", pattern(5, 3));
  EXPECT_EQ(vsd::io::read_file(dir.path / "data" / "new.bin"), pattern(5, 3));
  EXPECT_EQ(entries(dir.path / "data"), 2u) << "no temporary file left";
  // A loop is an error that says so.
  fs::create_symlink(dir.path / "b", dir.path / "a");
  fs::create_symlink(dir.path / "a", dir.path / "b");
  EXPECT_THAT([&] { vsd::io::write_file_atomically(dir.path / "a", pattern(5, 3)); },
              ThrowsMessage<vsd::Error>(HasSubstr("(a loop?)")));
}

TEST(AtomicFile, KeepsTheModeAndGivesNewFilesTheUmaskDefault) {
  TempDir dir;
  const fs::path file = dir.path / "secret.bin";
  vsd::io::write_file_atomically(file, pattern(10, 1));
  const mode_t mask = ::umask(0);
  ::umask(mask);
  EXPECT_EQ(mode_of(file) & 07777, 0666 & ~mask) << "a new file: 0666 less the umask";
  ASSERT_EQ(::chmod(file.c_str(), 0600), 0);
  vsd::io::write_file_atomically(file, pattern(10, 2));
  EXPECT_EQ(mode_of(file) & 07777, 0600u) << "a 0600 file stays 0600";
  ASSERT_EQ(::chmod(file.c_str(), 0664), 0);
  vsd::io::write_file_atomically(file, pattern(10, 3));
  EXPECT_EQ(mode_of(file) & 07777, 0664u) << "the umask does not narrow an existing file's mode";
}

TEST(AtomicFile, RefusesReadOnlyFilesEvenForRoot) {
  TempDir dir;
  const fs::path file = dir.path / "frozen.bin";
  vsd::io::write_file_atomically(file, pattern(10, 1));
  ASSERT_EQ(::chmod(file.c_str(), 0444), 0);
  EXPECT_THAT([&] { vsd::io::write_file_atomically(file, pattern(10, 2)); },
              ThrowsMessage<vsd::Error>(HasSubstr("frozen.bin: is read-only (mode 0444): not replaced")));
  EXPECT_EQ(vsd::io::read_file(file), pattern(10, 1));
  EXPECT_EQ(entries(dir.path), 1u);
}

TEST(AtomicFile, RefusesWhatIsNotARegularFile) {
  TempDir dir;
  fs::create_directories(dir.path / "folder");
  EXPECT_THAT(
      [&] { vsd::io::write_file_atomically(dir.path / "folder", pattern(4, 0)); },
      ThrowsMessage<vsd::Error>(HasSubstr("folder: is a directory: only a regular file is replaced")));
  ASSERT_EQ(::mkfifo((dir.path / "pipe").c_str(), 0644), 0);
  EXPECT_THAT([&] { vsd::io::write_file_atomically(dir.path / "pipe", pattern(4, 0)); },
              ThrowsMessage<vsd::Error>(HasSubstr("pipe: is a pipe (FIFO)")));
  EXPECT_EQ(mode_of(dir.path / "pipe") & S_IFMT, static_cast<mode_t>(S_IFIFO)) << "left as it was";
  // A device, also through a link (as root the old writer replaced /dev/full with a regular file).
  fs::create_symlink("/dev/full", dir.path / "full");
  EXPECT_THAT([&] { vsd::io::write_file_atomically(dir.path / "full", pattern(4, 0)); },
              ThrowsMessage<vsd::Error>(HasSubstr("/dev/full: is a character device (the target of ")));
  EXPECT_EQ(mode_of("/dev/full") & S_IFMT, static_cast<mode_t>(S_IFCHR));
  EXPECT_EQ(entries(dir.path), 3u);
}

TEST(AtomicFile, AnyLegalNameWorks) {
  TempDir dir;
  const fs::path file = dir.path / std::string(255, 'n');  // NAME_MAX: no room for a longer temporary
  vsd::io::write_file_atomically(file, pattern(10, 1));
  vsd::io::write_file_atomically(file, pattern(10, 2));
  EXPECT_EQ(vsd::io::read_file(file), pattern(10, 2));
  EXPECT_EQ(entries(dir.path), 1u);
}

// A write that fails half way (here: the file size limit, as a full disk would) leaves the old file whole
// and no temporary file behind.
TEST(AtomicFile, AFailedWriteLeavesTheOldFileWhole) {
  TempDir dir;
  const fs::path file = dir.path / "model.bin";
  vsd::io::write_file_atomically(file, pattern(1000, 1));
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {  // the limit in a child process: the test process keeps its own
    ::signal(SIGXFSZ, SIG_IGN);
    const rlimit small{4096, RLIM_INFINITY};
    ::setrlimit(RLIMIT_FSIZE, &small);
    try {
      vsd::io::write_file_atomically(file, pattern(100000, 2));
    } catch (const vsd::Error& e) {
      const std::string what = e.what();
      ::_exit(what.find("model.bin: cannot write the new contents (the old file is unchanged)") !=
                      std::string::npos
                  ? 0
                  : 2);
    }
    ::_exit(1);
  }
  int status = 0;
  ::waitpid(child, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0) << "1: the write did not fail, 2: the message is not the expected one";
  EXPECT_EQ(vsd::io::read_file(file), pattern(1000, 1));
  EXPECT_EQ(entries(dir.path), 1u) << "no temporary file left";
}

// The same with a real full disk, where the test may mount a small tmpfs (as root).
TEST(AtomicFile, AFullDiskLeavesTheOldFileWhole) {
  TempDir dir;
  const fs::path mnt = dir.path / "small";
  fs::create_directories(mnt);
  if (::mount("vsd_test", mnt.c_str(), "tmpfs", 0, "size=64k") != 0)
    GTEST_SKIP() << "cannot mount a tmpfs here";
  struct Unmount {
    fs::path at;
    ~Unmount() { ::umount(at.c_str()); }
  } unmount{mnt};
  const fs::path file = mnt / "model.bin";
  vsd::io::write_file_atomically(file, pattern(20000, 1));
  EXPECT_THAT([&] { vsd::io::write_file_atomically(file, pattern(200000, 2)); },
              ThrowsMessage<vsd::Error>(HasSubstr("No space left on device")));
  EXPECT_EQ(vsd::io::read_file(file), pattern(20000, 1));
  EXPECT_EQ(entries(mnt), 1u);
}

TEST(ReadFile, SaysWhatIsNotAFile) {
  TempDir dir;
  EXPECT_THAT([&] { (void)vsd::io::read_file(dir.path); },
              ThrowsMessage<vsd::Error>(HasSubstr(dir.path.string() + ": is a directory, not a file")));
}

TEST(ReadFile, AFileLargerThanMemoryIsAnErrorBeforeAnythingIsAllocated) {
  VSD_TEST_RUN_CAPPED();
  TempDir dir;
  const fs::path big = dir.path / "big.bin";
  { std::ofstream(big, std::ios::binary).put('x'); }
  fs::resize_file(big, std::size_t{1} << 30);  // sparse: no disk used
  vsd_test::cap_memory(std::size_t{64} << 20);
  EXPECT_THAT([&] { (void)vsd::io::read_file(big); },
              ThrowsMessage<vsd::Error>(HasSubstr(
                  "big.bin: a file of 1073741824 bytes does not fit the memory this process may use")));
}

TEST(ReadFile, ReadsPipesAndDevicesAsBoundedStreams) {
  TempDir dir;
  const fs::path fifo = dir.path / "pipe";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0644), 0);
  std::thread writer([&] {
    std::ofstream out(fifo, std::ios::binary);
    const auto bytes = pattern(300000, 4);
    out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  });
  EXPECT_EQ(vsd::io::read_file(fifo), pattern(300000, 4));
  writer.join();
  // An endless device stops at the limit with an error, never a bogus size.
  EXPECT_THAT(
      [&] { (void)vsd::io::read_file("/dev/zero", 100000); },
      ThrowsMessage<vsd::Error>(HasSubstr("/dev/zero: the stream goes on past the limit of 100000 bytes")));
  EXPECT_TRUE(vsd::io::read_file("/dev/null").empty());
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
