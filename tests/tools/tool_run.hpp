// What the tool tests share: a tool run in-process with its output captured, standard input fed from a
// string through a pipe, and a scratch directory. (One header: the test files compile together in a unity
// build, so none of them defines these itself.)
#pragma once

#include <fcntl.h>
#include <sys/resource.h>
#include <unistd.h>

#include <csignal>

#include <filesystem>
#include <fstream>
#include <span>
#include <sstream>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

namespace vsd_tool_test {

struct ToolRun {
  int code = 0;
  std::string out, err;
};

using Entry = int (*)(std::span<const std::string_view>, std::ostream&, std::ostream&);

inline ToolRun run_tool(Entry entry, const std::vector<std::string>& args) {
  const std::vector<std::string_view> views(args.begin(), args.end());
  std::ostringstream out, err;
  ToolRun r;
  r.code = entry(views, out, err);
  r.out = out.str();
  r.err = err.str();
  return r;
}

/// While alive, writing to a pipe nobody reads fails with EPIPE instead of killing the process (a tool
/// that stops reading its input early, on an error).
class IgnoreSigpipe {
 public:
  IgnoreSigpipe() : old_(std::signal(SIGPIPE, SIG_IGN)) {}
  ~IgnoreSigpipe() { std::signal(SIGPIPE, old_); }
  IgnoreSigpipe(const IgnoreSigpipe&) = delete;
  IgnoreSigpipe& operator=(const IgnoreSigpipe&) = delete;

 private:
  void (*old_)(int);
};

/// run_tool() with @p input on standard input, written through a pipe by another thread (so the tool reads
/// a stream, not a file).
inline ToolRun run_tool_with_stdin(Entry entry, const std::vector<std::string>& args, const std::string& input) {
  const IgnoreSigpipe no_sigpipe;
  int fds[2];
  if (::pipe(fds) != 0) return {-1, "", "pipe failed"};
  const int saved = ::dup(STDIN_FILENO);
  ::dup2(fds[0], STDIN_FILENO);
  ::close(fds[0]);
  std::thread writer([fd = fds[1], &input] {
    std::size_t at = 0;
    while (at < input.size()) {
      const ssize_t n = ::write(fd, input.data() + at, input.size() - at);
      if (n <= 0) break;
      at += static_cast<std::size_t>(n);
    }
    ::close(fd);
  });
  ToolRun r = run_tool(entry, args);
  writer.join();
  ::dup2(saved, STDIN_FILENO);
  ::close(saved);
  return r;
}

/// A scratch directory of this process, removed with everything in it.
class TempDir {
 public:
  explicit TempDir(const std::string& name)
      : dir_(std::filesystem::temp_directory_path() / (name + "_" + std::to_string(::getpid()))) {
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::permissions(dir_, std::filesystem::perms::owner_all, ec);
    std::filesystem::remove_all(dir_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  [[nodiscard]] std::string path(const std::string& name) const { return (dir_ / name).string(); }
  [[nodiscard]] const std::filesystem::path& dir() const { return dir_; }
  /// Writes @p text to file @p name and returns its path.
  std::string write(const std::string& name, const std::string& text) const {
    std::ofstream(dir_ / name, std::ios::binary) << text;
    return path(name);
  }
  [[nodiscard]] static std::string read(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  }

 private:
  std::filesystem::path dir_;
};

/// While alive, no file of this process can grow beyond @p bytes: a write past it fails with EFBIG
/// (SIGXFSZ is ignored meanwhile). A full disk, for root too.
class FileSizeLimit {
 public:
  explicit FileSizeLimit(rlim_t bytes) {
    ::getrlimit(RLIMIT_FSIZE, &saved_);
    old_handler_ = std::signal(SIGXFSZ, SIG_IGN);
    rlimit r = saved_;
    r.rlim_cur = bytes;
    ::setrlimit(RLIMIT_FSIZE, &r);
  }
  ~FileSizeLimit() {
    ::setrlimit(RLIMIT_FSIZE, &saved_);
    std::signal(SIGXFSZ, old_handler_);
  }
  FileSizeLimit(const FileSizeLimit&) = delete;
  FileSizeLimit& operator=(const FileSizeLimit&) = delete;

 private:
  rlimit saved_{};
  void (*old_handler_)(int) = nullptr;
};

inline bool has(const std::string& text, const std::string& piece) { return text.find(piece) != std::string::npos; }

}  // namespace vsd_tool_test
