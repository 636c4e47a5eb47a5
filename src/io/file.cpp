#include "vsd/io/file.hpp"

#include <fcntl.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <new>
#include <random>
#include <string>

#include "vsd/core/error.hpp"

namespace vsd::io {

namespace {

namespace fs = std::filesystem;

[[noreturn]] void fail(const fs::path& path, const std::string& what, int error = 0) {
  throw Error(path.string() + ": " + what +
              (error != 0 ? std::string(": ") + std::strerror(error) : std::string()));
}

std::string mode_text(mode_t mode) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "%04o", static_cast<unsigned>(mode & 07777));
  return buf;
}

// What a file that is not a regular file is, for messages.
std::string kind_of(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISFIFO(mode)) return "a pipe (FIFO)";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

// The file a write to @p path lands in: @p path itself, or the final target of the chain of symbolic
// links it names (relative links resolve against the link's own directory). A loop, or a chain longer
// than the system would follow, is an error.
fs::path final_target(const fs::path& path) {
  constexpr int max_links = 40;  // Linux's own limit (ELOOP)
  fs::path at = path;
  for (int hops = 0;; ++hops) {
    struct stat st {};
    if (::lstat(at.c_str(), &st) != 0 || !S_ISLNK(st.st_mode)) return at;
    if (hops == max_links)
      fail(path, "symbolic links nest deeper than " + std::to_string(max_links) + " (a loop?)");
    std::error_code ec;
    const fs::path target = fs::read_symlink(at, ec);
    if (ec) fail(at, "cannot read the symbolic link", ec.value());
    at = target.is_absolute() ? target : at.parent_path() / target;
  }
}

// Closes a descriptor and removes the temporary file unless the write went through.
struct TempFile {
  fs::path path;
  int fd = -1;
  bool keep = false;
  ~TempFile() {
    if (fd >= 0) ::close(fd);
    if (!keep) ::unlink(path.c_str());
  }
};

// A new, empty file in @p dir under a short random name (so that any legal target name works) with
// @p mode (the umask applies), open for writing.
void create_temporary(const fs::path& dir, mode_t mode, TempFile& tmp) {
  std::random_device rd;
  for (int attempt = 0;; ++attempt) {
    char name[32];
    std::snprintf(name, sizeof name, ".vsd-%08x.tmp", static_cast<unsigned>(rd()));
    tmp.path = dir / name;
    tmp.fd = ::open(tmp.path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, mode);
    if (tmp.fd >= 0) return;
    if (errno != EEXIST || attempt == 100) {
      const int error = errno;
      tmp.keep = true;  // nothing was made: nothing to remove (and the name may be somebody else's)
      fail(dir, "cannot create a temporary file in this directory", error);
    }
  }
}

void write_all(const fs::path& path, int fd, std::span<const std::uint8_t> bytes) {
  for (std::size_t done = 0; done < bytes.size();) {
    const std::size_t chunk = std::min<std::size_t>(bytes.size() - done, std::size_t{1} << 30);
    const ssize_t n = ::write(fd, bytes.data() + done, chunk);
    if (n < 0) {
      const int error = errno;
      if (error == EINTR) continue;
      fail(path, "cannot write the new contents (the old file is unchanged)", error);
    }
    if (n == 0) fail(path, "cannot write the new contents (the old file is unchanged): no progress");
    done += static_cast<std::size_t>(n);
  }
}

// The memory this process may use, as far as the system says: the smaller of the physical memory and
// the address-space and data limits (0: unknown).
std::uint64_t memory_bound() {
  std::uint64_t bound = 0;
  auto take = [&](std::uint64_t v) {
    if (v != 0 && (bound == 0 || v < bound)) bound = v;
  };
  const long pages = ::sysconf(_SC_PHYS_PAGES);
  const long page = ::sysconf(_SC_PAGESIZE);
  if (pages > 0 && page > 0) take(static_cast<std::uint64_t>(pages) * static_cast<std::uint64_t>(page));
  for (const int resource : {RLIMIT_AS, RLIMIT_DATA}) {
    struct rlimit limit {};
    if (::getrlimit(resource, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY) take(limit.rlim_cur);
  }
  return bound;
}

}  // namespace

void write_file_atomically(const fs::path& path, std::span<const std::uint8_t> bytes) {
  const fs::path target = final_target(path);
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  const std::string via = target == path ? std::string() : " (the target of " + path.string() + ")";
  struct stat st {};
  const bool exists = ::stat(target.c_str(), &st) == 0;
  if (!exists && errno != ENOENT) {
    const int error = errno;
    fail(target, "cannot look at the file" + via, error);
  }
  mode_t mode = 0666;  // a new file: what the umask leaves of it
  if (exists) {
    // A save replaces a file of data, never a directory, a device or a pipe; it keeps the file's mode,
    // and leaves a read-only file alone, even when the system would let the user (root) replace it.
    if (!S_ISREG(st.st_mode))
      fail(target, "is " + kind_of(st.st_mode) + via + ": only a regular file is replaced");
    if ((st.st_mode & (S_IWUSR | S_IWGRP | S_IWOTH)) == 0)
      fail(target, "is read-only (mode " + mode_text(st.st_mode) + ")" + via + ": not replaced");
    if (::faccessat(AT_FDCWD, target.c_str(), W_OK, AT_EACCESS) != 0)
      fail(target,
           "is not writable by this user (mode " + mode_text(st.st_mode) + ")" + via + ": not replaced");
    mode = st.st_mode & 07777;
  }
  TempFile tmp;
  create_temporary(dir, mode, tmp);
  if (exists) {
    // The umask must not narrow the mode of an existing file. The owner stays where the system lets it
    // (root saving another user's file); else the file becomes the saver's, as a new file would.
    if (::fchmod(tmp.fd, mode) != 0) {
      const int error = errno;
      fail(tmp.path, "cannot set the mode " + mode_text(mode), error);
    }
    if ((st.st_uid != ::geteuid() || st.st_gid != ::getegid()) &&
        ::fchown(tmp.fd, st.st_uid, st.st_gid) != 0) {
      [[maybe_unused]] const int group_kept = ::fchown(tmp.fd, static_cast<uid_t>(-1), st.st_gid);
    }
  }
  write_all(target, tmp.fd, bytes);
  if (::fsync(tmp.fd) != 0) {
    const int error = errno;
    fail(target, "cannot flush the new contents to disk (the old file is unchanged)", error);
  }
  const int closed = ::close(tmp.fd);
  const int close_error = errno;
  tmp.fd = -1;
  if (closed != 0) fail(target, "cannot write the new contents (the old file is unchanged)", close_error);
  if (::rename(tmp.path.c_str(), target.c_str()) != 0) {
    const int error = errno;
    fail(target, "cannot replace the file" + via, error);
  }
  tmp.keep = true;
  // Make the rename itself durable: flush the directory (a file system that cannot is not an error).
  const int dfd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dfd < 0) {
    const int error = errno;
    fail(dir, "the new file is in place, but its directory cannot be opened to flush it", error);
  }
  const int synced = ::fsync(dfd);
  const int sync_error = errno;
  ::close(dfd);
  if (synced != 0 && sync_error != EINVAL && sync_error != EROFS)
    fail(dir, "the new file is in place, but its directory cannot be flushed to disk", sync_error);
}

std::vector<std::uint8_t> read_file(const fs::path& path, std::size_t max_bytes) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) {
    const int error = errno;
    fail(path, "cannot open", error);
  }
  struct Closer {
    int fd;
    ~Closer() { ::close(fd); }
  } closer{fd};
  struct stat st {};
  if (::fstat(fd, &st) != 0) {
    const int error = errno;
    fail(path, "cannot look at the file", error);
  }
  if (S_ISDIR(st.st_mode)) fail(path, "is a directory, not a file");
  // A regular file says its size: it is checked before anything is allocated. Anything else (a pipe,
  // standard input, a character device) is read as a stream until it ends, up to the same limit.
  const bool sized = S_ISREG(st.st_mode);
  const std::uint64_t size = sized ? static_cast<std::uint64_t>(st.st_size) : 0;
  if (size > max_bytes)
    fail(path,
         "a file of " + std::to_string(size) + " bytes exceeds the limit of " + std::to_string(max_bytes));
  if (const std::uint64_t memory = memory_bound(); memory != 0 && size > memory)
    fail(path, "a file of " + std::to_string(size) + " bytes does not fit the memory this process may use (" +
                   std::to_string(memory) + " bytes)");
  auto read_some = [&](void* into, std::size_t n) -> std::size_t {
    while (true) {
      const ssize_t got = ::read(fd, into, n);
      if (got >= 0) return static_cast<std::size_t>(got);
      const int error = errno;
      if (error != EINTR) fail(path, "cannot read", error);
    }
  };
  std::vector<std::uint8_t> bytes;
  try {
    bytes.resize(static_cast<std::size_t>(size));
    std::size_t done = 0;
    while (done < bytes.size()) {
      const std::size_t n = read_some(bytes.data() + done, bytes.size() - done);
      if (n == 0) break;  // the file shrank meanwhile
      done += n;
    }
    bytes.resize(done);
    // The rest: a stream, or a file that grew meanwhile.
    std::uint8_t chunk[1 << 16];
    while (const std::size_t n = read_some(chunk, sizeof chunk)) {
      if (n > max_bytes - bytes.size())
        fail(path, std::string(sized ? "the file grew past" : "the stream goes on past") + " the limit of " +
                       std::to_string(max_bytes) + " bytes");
      bytes.insert(bytes.end(), chunk, chunk + n);
    }
  } catch (const std::bad_alloc&) {
    fail(path,
         "out of memory reading " + (sized ? "a file of " + std::to_string(size) + " bytes" : "the stream"));
  }
  return bytes;
}

}  // namespace vsd::io
