#include "core/file_io.hpp"

#include <fcntl.h>
#include <poll.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "core/host_memory.hpp"
#include "lucent/error.hpp"

namespace lucent::io {

namespace fs = std::filesystem;

namespace {

std::string reason(int err) { return std::strerror(err); }

// Closes the descriptor on every path out of a function.
struct Fd {
  int fd = -1;
  explicit Fd(int f) : fd(f) {}
  ~Fd() {
    if (fd >= 0) ::close(fd);
  }
  Fd(const Fd&) = delete;
  Fd& operator=(const Fd&) = delete;
};

// "a texture", "an image", "an OBJ file", "an MTL file": the article for a kind of file.
std::string a(const std::string& what) {
  if (what.empty()) return "a file";
  const char c = what[0];
  bool vowel = std::strchr("aeiouAEIOU", c) != nullptr;
  bool acronym = what.size() > 1 && std::isupper(static_cast<unsigned char>(what[1])) &&
                 std::strchr("FHLMNRSX", c) != nullptr;  // em, ef, aitch, ...
  return (vowel || acronym ? "an " : "a ") + what;
}

const char* kind_of(mode_t mode) {
  if (S_ISCHR(mode) || S_ISBLK(mode)) return "a device";
  if (S_ISSOCK(mode)) return "a socket";
  if (S_ISFIFO(mode)) return "a pipe";
  return "not a regular file";
}

/// The file an output path writes: `path`, or where its chain of symbolic links ends, whether
/// that file exists or not (a link to a file not yet written is written through, as `>` does;
/// weakly_canonical cannot resolve such a link, and the link itself was replaced by the file).
/// A loop of links is an error.
fs::path write_target(const std::string& path) {
  fs::path target(path);
  std::error_code ec;
  for (int depth = 0; fs::is_symlink(target, ec); ++depth) {
    if (depth == 40)  // the kernel's own limit (ELOOP)
      throw Error(path + ": cannot write (" + reason(ELOOP) + ")");
    const fs::path link = fs::read_symlink(target, ec);
    if (ec) break;
    target = link.is_absolute() ? link : target.parent_path() / link;
  }
  return target;
}

/// Refuses to write over `target` (where `path` leads) when it exists and is not a regular file:
/// the temporary file renamed into place replaced a FIFO, a socket or a device node (a link to
/// /dev/null run as root replaced the device with the image), and never wrote into it.
void check_writable_kind(const std::string& path, const fs::path& target) {
  struct stat st {};
  if (::stat(target.c_str(), &st) != 0 || S_ISREG(st.st_mode) || S_ISDIR(st.st_mode)) return;
  throw Error(path + ": is " + kind_of(st.st_mode) +
              ", not a regular file (outputs are written to a temporary file renamed into place)");
}

// The temporary file a write of `name` into `dir` goes through: a hidden name beside it, of at
// most kTempNameBytes of the name, so that a name near the file system's limit (255 bytes) has
// one too (its whole name plus the suffix was refused, after the render).
constexpr size_t kTempNameBytes = 128;
fs::path temp_path(const fs::path& dir, const std::string& name) {
  static std::atomic<unsigned> counter{0};
  return dir / ("." + name.substr(0, kTempNameBytes) + ".tmp-" + std::to_string(::getpid()) + "-" +
                std::to_string(counter++));
}

// Creates a new temporary file for a write of `name` into `dir` (O_EXCL), its name in `tmp`;
// -1 and errno as open() when it cannot. A name taken by another file is passed over: a write
// killed half-way leaves its temporary file, and in a container (a pid namespace) the next run
// has the same pid and counter, so that every rerun rendered in full and then failed with
// "cannot write (File exists)" on a file the message did not name. A write holds an flock on its
// temporary file (write_file_atomic): one that no process holds is such a leftover, and goes
// (each killed rerun left another full-size hidden file beside the output).
// The new file is returned locked (flock, exclusive) and checked to be the file of its name: a
// process that took the name between the open and the lock (a leftover's reaper) makes the name
// retried. On a file system whose flock is not that (NFS emulates it with fcntl locks, which an
// exclusive lock needs the file open for writing for), the lock may fail: the file is used all
// the same, unlocked, and another run takes it for a leftover only where its lock succeeds.
int open_temp(const fs::path& dir, const std::string& name, mode_t mode, std::string& tmp) {
  for (int tries = 0;; ++tries) {
    tmp = temp_path(dir, name).string();
    int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, mode);
    if (fd < 0 && errno == EEXIST) {
      remove_if_unheld(tmp);  // (a killed write's; the name is retried)
      fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, mode);
      errno = fd < 0 ? errno : 0;
    }
    if (fd >= 0) {
      const int lock_error = ::flock(fd, LOCK_EX | LOCK_NB) == 0 ? 0 : errno;
      if (is_file_at(fd, tmp) && lock_error != EWOULDBLOCK) return fd;
      ::close(fd);  // (taken from under it: another name)
      errno = EEXIST;
    }
    if (errno != EEXIST || tries == 1000) return -1;
  }
}

// Whether `file` is a name temp_path(dir, name) gives: ".<name>.tmp-<digits>-<digits>".
bool is_temp_name(const std::string& file, const std::string& name) {
  const std::string head = "." + name + ".tmp-";
  if (file.compare(0, head.size(), head) != 0) return false;
  const std::string tail = file.substr(head.size());
  const size_t dash = tail.find('-');
  auto digits = [](const std::string& t) {
    return !t.empty() &&
           std::all_of(t.begin(), t.end(), [](char c) { return c >= '0' && c <= '9'; });
  };
  return dash != std::string::npos && digits(tail.substr(0, dash)) && digits(tail.substr(dash + 1));
}

}  // namespace

std::string format_size(std::uint64_t b) { return sys::format_bytes(b); }

void hold_standard_descriptors() {
  for (int fd = 0; fd < 3; ++fd) {
    if (::fcntl(fd, F_GETFD) != -1 || errno != EBADF) continue;
    // (the lowest free descriptor: fd itself, those below it being open)
    const int held = ::open("/dev/null", O_RDONLY);
    if (held >= 0 && held != fd) {
      ::dup2(held, fd);
      ::close(held);
    }
  }
}

std::string read_file(const std::string& path, const ReadSpec& spec) {
  const std::string what = spec.what;
  // O_NONBLOCK: opening a FIFO nobody writes to returns at once (a read then sees end of file)
  Fd f(::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY));
  if (f.fd < 0) throw Error(path + ": cannot open " + what + " (" + reason(errno) + ")");
  struct stat st {};
  if (::fstat(f.fd, &st) != 0)
    throw Error(path + ": cannot open " + what + " (" + reason(errno) + ")");
  if (S_ISDIR(st.st_mode)) throw Error(path + ": is a directory, not " + a(what));
  const bool regular = S_ISREG(st.st_mode);
  const bool pipe = S_ISFIFO(st.st_mode);
  if (!regular && !(pipe && spec.allow_pipe))
    throw Error(path + ": is " + kind_of(st.st_mode) + ", not " + a(what) +
                " (only regular files are read)");
  const std::uint64_t limit = spec.max_bytes;
  if (regular && static_cast<std::uint64_t>(st.st_size) > limit)
    throw Error(path + ": " + format_size(static_cast<std::uint64_t>(st.st_size)) +
                " is more than the " + format_size(limit) + " " + a(what) + " may have");
  // the descriptor stays non-blocking: a pipe is waited for with poll() below, with a bound

  std::string out;
  if (regular) out.reserve(static_cast<size_t>(st.st_size));
  char buf[1 << 16];
  for (;;) {
    ssize_t n = ::read(f.fd, buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && errno == EAGAIN && pipe) {
      struct pollfd p {
        f.fd, POLLIN, 0
      };
      int r = ::poll(&p, 1, spec.stream_idle_seconds * 1000);
      if (r < 0 && errno == EINTR) continue;
      if (r == 0)
        throw Error(path + ": no data for " + std::to_string(spec.stream_idle_seconds) +
                    " s after " + format_size(out.size()) + " (a pipe that never ends?)");
      continue;
    }
    if (n < 0) throw Error(path + ": cannot read " + what + " (" + reason(errno) + ")");
    if (n == 0) break;
    if (spec.text) {
      if (const void* z = std::memchr(buf, '\0', static_cast<size_t>(n))) {
        size_t at = out.size() + static_cast<size_t>(static_cast<const char*>(z) - buf);
        throw Error(path + ": byte " + std::to_string(at + 1) + " is a NUL byte: not a text " +
                    what);
      }
    }
    if (out.size() + static_cast<size_t>(n) > limit)
      throw Error(path + ": more than the " + format_size(limit) + " " + a(what) + " may have" +
                  (regular ? " (the file grew while being read)" : " (a stream that never ends?)"));
    out.append(buf, static_cast<size_t>(n));
  }
  return out;
}

std::string lower_extension(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

void unknown_output_format(const std::string& path, const std::string& ext, const char* formats) {
  if (ext.empty())
    throw Error(path + ": no extension to name the output format (use " + formats + ")");
  throw Error(path + ": unknown output format '" + ext + "' (use " + formats + ")");
}

void check_output_path(const std::string& out, const std::vector<std::string>& inputs,
                       bool is_checkpoint) {
  if (out.empty()) throw Error("-o: the output path is empty");
  std::error_code ec;
  if (fs::is_directory(out, ec)) throw Error(out + ": is a directory");
  std::string ext = lower_extension(out);
  if (ext != ".png" && ext != ".pfm" && ext != ".exr")
    unknown_output_format(out, ext, ".png, .pfm or .exr");
  check_output_file(out, inputs, is_checkpoint);
}

void check_output_file(const std::string& out, const std::vector<std::string>& inputs,
                       bool is_checkpoint) {
  // (a checkpoint's errors say "checkpoint": "cannot write output" named the wrong file's role)
  const std::string cannot =
      is_checkpoint ? ": cannot write checkpoint (" : ": cannot write output (";
  std::error_code ec;
  if (fs::is_directory(out, ec)) throw Error(out + ": is a directory");
  for (const std::string& in : inputs)
    if (same_file(out, in))
      throw Error(out + ": is an input of this render (" + in + "); refusing to overwrite it");
  if (fs::exists(out, ec) && ::access(out.c_str(), W_OK) != 0)
    throw Error(out + cannot + std::strerror(errno) + ")");
  const fs::path target = write_target(out);  // the directory the write will go to
  check_writable_kind(out, target);
  // the checkpoint of a render in progress (its lock held, lucent::cli::CheckpointLock): that
  // render's next write replaced the output with a part file, and its end removed it
  const std::string lock = target.string() + ".lock";
  if (int lfd =
          is_checkpoint ? -1 : ::open(lock.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK | O_NOCTTY);
      lfd >= 0) {
    char mark[sizeof kCheckpointLockMark] = {};
    const ssize_t n = ::pread(lfd, mark, sizeof mark - 1, 0);
    const bool held = n == ssize_t(sizeof mark - 1) &&
                      std::memcmp(mark, kCheckpointLockMark, sizeof mark - 1) == 0 &&
                      ::flock(lfd, LOCK_SH | LOCK_NB) != 0 && errno == EWOULDBLOCK;
    ::close(lfd);
    if (held)
      throw Error(out + ": is the checkpoint of a render in progress (" + lock +
                  " is locked): give the output another name");
  }
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  const std::string name = target.filename().string();
  // the name itself, which only the final rename would refuse
  const long name_max = ::pathconf(dir.c_str(), _PC_NAME_MAX);
  if (name_max > 0 && name.size() > static_cast<size_t>(name_max))
    throw Error(out + cannot + "a file name of " + std::to_string(name.size()) +
                " bytes, more than the " + std::to_string(name_max) + " this file system allows)");
  // the temporary file the write goes through
  std::string probe;
  int fd = open_temp(dir, name, 0600, probe);
  if (fd < 0) throw Error(out + cannot + std::strerror(errno) + ")");
  ::unlink(probe.c_str());  // (while it holds the lock: the name is no one else's yet)
  ::close(fd);
}

bool remove_if_unheld(const std::string& path) {
  struct stat st {};
  if (::lstat(path.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) return false;
  int fd = ::open(path.c_str(), O_RDWR | O_NOFOLLOW | O_NONBLOCK | O_NOCTTY | O_CLOEXEC);
  if (fd < 0) fd = ::open(path.c_str(), O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_NOCTTY | O_CLOEXEC);
  if (fd < 0) return false;
  // (a FIFO or a device put there since the lstat is not removed either)
  struct stat opened {};
  const bool removed = ::fstat(fd, &opened) == 0 && S_ISREG(opened.st_mode) &&
                       ::flock(fd, LOCK_EX | LOCK_NB) == 0 && is_file_at(fd, path) &&
                       ::unlink(path.c_str()) == 0;
  ::close(fd);
  return removed;
}

bool is_file_at(int fd, const std::string& path) {
  struct stat open_file, named;
  return ::fstat(fd, &open_file) == 0 && ::stat(path.c_str(), &named) == 0 &&
         open_file.st_ino == named.st_ino && open_file.st_dev == named.st_dev;
}

bool same_file(const std::string& a, const std::string& b) {
  std::error_code ec;
  if (fs::exists(a, ec) && fs::exists(b, ec)) return fs::equivalent(a, b, ec) && !ec;
  // a path not there yet: where a write of it goes (through a link to a file not yet written),
  // made absolute first (libstdc++'s weakly_canonical left "out.exr" relative, when no part of
  // it exists, and made "./out.exr" absolute: the two were different files, and `lucent render
  // -o ./out.exr --checkpoint out.exr` removed its output as the finished checkpoint)
  auto where = [&ec](const std::string& p) {
    fs::path t;
    try {
      t = write_target(p);
    } catch (const Error&) {
      t = p;  // (a loop of links: as given)
    }
    t = fs::absolute(t, ec);
    return ec ? fs::path() : fs::weakly_canonical(t, ec);
  };
  const fs::path ca = where(a);
  if (ec || ca.empty()) return false;
  const fs::path cb = where(b);
  return !ec && ca == cb;
}

void write_all(int fd, const void* data, std::size_t size, const std::string& path) {
  const char* p = static_cast<const char*>(data);
  while (size > 0) {
    ssize_t n = ::write(fd, p, size);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw Error(path + ": cannot write (" + reason(errno) + ")");
    if (n == 0) throw Error(path + ": cannot write (the device accepts no more data)");
    p += n;
    size -= static_cast<std::size_t>(n);
  }
}

std::string write_target_path(const std::string& path) { return write_target(path).string(); }

int remove_stale_temporaries(const std::string& path) {
  std::error_code ec;
  const fs::path target = write_target(path);
  const std::string name = target.filename().string();
  if (name.empty() || name == "." || name == ".." || name.size() > kTempNameBytes) return 0;
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  int removed = 0;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    // the entry itself, not where it leads: write_file_atomic makes regular files, and a
    // symbolic link of that name is someone else's (is_regular_file followed it, and removed a
    // link to a regular file)
    std::error_code type_ec;
    if (!is_temp_name(it->path().filename().string(), name) ||
        !fs::is_regular_file(it->symlink_status(type_ec)))
      continue;
    removed += remove_if_unheld(it->path().string()) ? 1 : 0;  // (not a write in progress)
  }
  return removed;
}

void write_file_atomic(const std::string& path, const void* data, std::size_t size) {
  // write where a symbolic link points: replacing the link itself would surprise
  const fs::path target = write_target(path);
  const std::string name = target.filename().string();
  if (name.empty() || name == "." || name == "..")
    throw Error(path + ": cannot write (not a file name)");
  check_writable_kind(path, target);
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  std::string tmp;
  // locked while the write lasts, its rename included: a file of its name that no process holds
  // is a killed write's leftover (open_temp)
  int fd = open_temp(dir, name, 0666, tmp);
  if (fd < 0) throw Error(path + ": cannot write (" + reason(errno) + ")");
  // a file replaced keeps its permissions (a new file's mode comes from the umask: a private
  // image became readable by all), set before any byte is written; as it is a new file, its
  // other hard links keep the old content
  struct stat old;
  if (::stat(target.c_str(), &old) == 0 && S_ISREG(old.st_mode))
    (void)::fchmod(fd, old.st_mode & 07777);
  auto fail = [&](int err) {
    if (fd >= 0) ::close(fd);
    ::unlink(tmp.c_str());
    throw Error(path + ": cannot write (" + reason(err) + ")");
  };
  try {
    write_all(fd, data, size, path);
  } catch (const Error&) {
    ::close(fd);
    ::unlink(tmp.c_str());
    throw;
  }
  // a full disk or an I/O error may only show when the data reaches the device
  if (::fsync(fd) != 0 && errno != EINVAL && errno != EROFS) fail(errno);
  // the lock kept through the rename by a second descriptor (closing the first, whose error
  // counts, released it: a finished file could be taken for a leftover before its rename)
  const int held = ::dup(fd);
  int rc = ::close(fd);
  fd = held;
  if (rc != 0 && errno != EINTR) fail(errno);
  if (::rename(tmp.c_str(), target.c_str()) != 0) fail(errno);
  if (fd >= 0) ::close(fd);
}

}  // namespace lucent::io
