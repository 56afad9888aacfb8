// Reading inputs without blocking and writing outputs whole or not at all (cf/file_io.hpp).

#include <cf/file_io.hpp>
#include <cf/polyhedron.hpp>
#include <cf/types.hpp>

#include "input_file.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iterator>
#include <mutex>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace cf {

namespace {

std::string lower_first(std::string s) {
  if (!s.empty() && s[0] >= 'A' && s[0] <= 'Z') s[0] = static_cast<char>(s[0] - 'A' + 'a');
  return s;
}

std::string errno_text(int e) { return lower_first(std::strerror(e)); }

/// "a directory", "a FIFO (named pipe)", ... for a file that is not a regular one.
std::string kind_of(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO (named pipe)";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

std::string dir_of(const std::string& path) {
  const std::size_t slash = path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  return slash == 0 ? "/" : path.substr(0, slash);
}

/// Follows symlinks (up to 40) to the path that a write through `path` would replace.
/// A dangling link resolves to the path it names. Sets `why` when the chain is too long or
/// a link cannot be read.
std::string resolve_links(const std::string& path, std::string& why) {
  std::string p = path;
  for (int hops = 0; hops < 40; ++hops) {
    struct stat st {};
    if (::lstat(p.c_str(), &st) != 0 || !S_ISLNK(st.st_mode)) return p;
    std::string target(static_cast<std::size_t>(st.st_size > 0 ? st.st_size : 255) + 1, '\0');
    const ssize_t n = ::readlink(p.c_str(), target.data(), target.size());
    if (n < 0) {
      why = "cannot read the symbolic link: " + errno_text(errno);
      return p;
    }
    target.resize(static_cast<std::size_t>(n));
    p = (!target.empty() && target[0] == '/') ? target : dir_of(p) + "/" + target;
  }
  why = "too many levels of symbolic links";
  return p;
}

/// "<target>.tmp-XXXXXX" for mkstemp, the target's name cut short when the whole would be
/// longer than the file system's names (a 250-byte output name is legal; its temporary too).
std::string temp_name(const std::string& target) {
  static constexpr char kSuffix[] = ".tmp-XXXXXX";
  const std::size_t slash = target.find_last_of('/');
  const std::size_t name_start = slash == std::string::npos ? 0 : slash + 1;
  const long name_max = ::pathconf(dir_of(target).c_str(), _PC_NAME_MAX);
  const std::size_t room =
      name_max > 0 ? static_cast<std::size_t>(name_max) - (sizeof kSuffix - 1) : target.size();
  return target.substr(0, name_start + std::min(target.size() - name_start, room)) + kSuffix;
}

[[noreturn]] void refuse(const char* what, const std::string& path, const std::string& why) {
  throw FileError(std::string(what) + " '" + path + "': " + why);
}

/// The file a write to `path` would replace, after the checks of check_output_path.
std::string checked_target(const std::string& path, const std::vector<std::string>& inputs,
                           const char* what) {
  if (path.empty()) refuse(what, path, "empty file name");
  if (path.back() == '/') refuse(what, path, "names a directory, not a file");
  std::string why;
  const std::string target = resolve_links(path, why);
  if (!why.empty()) refuse(what, path, why);
  struct stat st {};
  if (::stat(target.c_str(), &st) == 0) {
    if (!S_ISREG(st.st_mode))
      refuse(what, path, "is " + kind_of(st.st_mode) + "; output files must be regular files");
    for (const std::string& in : inputs) {
      struct stat si {};
      if (::stat(in.c_str(), &si) == 0 && si.st_dev == st.st_dev && si.st_ino == st.st_ino)
        refuse(what, path,
               in == path ? "is an input of this run; refusing to overwrite it"
                          : "is the same file as the input '" + in + "'; refusing to overwrite it");
    }
  } else if (errno != ENOENT) {
    refuse(what, path, "cannot check the path: " + errno_text(errno));
  }
  const std::string dir = dir_of(target);
  struct stat sd {};
  if (::stat(dir.c_str(), &sd) != 0)
    refuse(what, path,
           "the directory '" + dir + "' " +
               (errno == ENOENT ? std::string("does not exist")
                                : "cannot be checked: " + errno_text(errno)));
  if (!S_ISDIR(sd.st_mode)) refuse(what, path, "'" + dir + "' is not a directory");
  const long name_max = ::pathconf(dir.c_str(), _PC_NAME_MAX);
  const std::size_t name_len = target.size() - target.find_last_of('/') - 1;
  if (name_max > 0 && name_len > static_cast<std::size_t>(name_max))
    refuse(what, path,
           "the file name is " + std::to_string(name_len) + " bytes, longer than the " +
               std::to_string(name_max) + " the file system takes");
  if (::access(dir.c_str(), W_OK) != 0)
    refuse(what, path, "the directory '" + dir + "' is not writable: " + errno_text(errno));
  return target;
}

// ---- Temporary files removed when a signal ends the process mid-write ----
//
// While outputs are written, SIGINT, SIGTERM and SIGHUP, where they would end the process
// (their disposition is the default), first remove the temporary files being written, then
// end it as the default would. A signal the program handles itself (cfgen's stop between
// tasks, Python's KeyboardInterrupt) or ignores is left alone: the write then finishes, or
// fails and cleans up, as usual.

constexpr int kCleanupSignals[] = {SIGINT, SIGTERM, SIGHUP};
constexpr int kTempSlots = 32;
char g_temp_path[kTempSlots][4096];
std::atomic<bool> g_temp_used[kTempSlots];

extern "C" void remove_temps_and_die(int sig) {
  for (int i = 0; i < kTempSlots; ++i)
    if (g_temp_used[i].load()) ::unlink(g_temp_path[i]);
  std::signal(sig, SIG_DFL);
  std::raise(sig);
}

/// Installs the handler for the signals left at their default while some write is in
/// progress (the first one in), and puts the defaults back after the last one.
class SignalCleanup {
 public:
  SignalCleanup() {
    const std::lock_guard<std::mutex> lock(mutex());
    if (active()++ > 0) return;
    for (std::size_t k = 0; k < std::size(kCleanupSignals); ++k) {
      struct sigaction old {};
      installed()[k] = sigaction(kCleanupSignals[k], nullptr, &old) == 0 &&
                       !(old.sa_flags & SA_SIGINFO) && old.sa_handler == SIG_DFL;
      if (!installed()[k]) continue;
      struct sigaction sa {};
      sa.sa_handler = remove_temps_and_die;
      sigemptyset(&sa.sa_mask);
      sigaction(kCleanupSignals[k], &sa, nullptr);
    }
  }
  ~SignalCleanup() {
    const std::lock_guard<std::mutex> lock(mutex());
    if (--active() > 0) return;
    for (std::size_t k = 0; k < std::size(kCleanupSignals); ++k)
      if (installed()[k]) std::signal(kCleanupSignals[k], SIG_DFL);
  }
  SignalCleanup(const SignalCleanup&) = delete;
  SignalCleanup& operator=(const SignalCleanup&) = delete;

  /// Registers a temporary file (its slot, or -1 when every slot is taken or the path is
  /// too long: that file is then only removed by the usual paths).
  static int add(const std::string& path) {
    if (path.size() >= sizeof g_temp_path[0]) return -1;
    for (int i = 0; i < kTempSlots; ++i) {
      bool expected = false;
      if (!g_temp_used[i].load() && claimed()[i].compare_exchange_strong(expected, true)) {
        std::memcpy(g_temp_path[i], path.c_str(), path.size() + 1);
        g_temp_used[i].store(true);
        return i;
      }
    }
    return -1;
  }
  static void remove(int slot) {
    if (slot < 0) return;
    g_temp_used[slot].store(false);
    claimed()[slot].store(false);
  }

 private:
  static std::mutex& mutex() {
    static std::mutex m;
    return m;
  }
  static int& active() {
    static int n = 0;
    return n;
  }
  static std::array<bool, std::size(kCleanupSignals)>& installed() {
    static std::array<bool, std::size(kCleanupSignals)> on{};
    return on;
  }
  static std::array<std::atomic<bool>, kTempSlots>& claimed() {
    static std::array<std::atomic<bool>, kTempSlots> c{};
    return c;
  }
};

}  // namespace

namespace internal {

int open_input_file(const std::string& path, std::string& why, std::size_t max_bytes) {
  if (path.empty()) {
    why = "empty file name";
    return -1;
  }
  // O_NONBLOCK: opening a FIFO for reading then returns at once instead of waiting for a
  // writer; fstat tells what it is before anything is read.
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
  if (fd < 0) {
    why = errno == ENOENT ? std::string("no such file") : errno_text(errno);
    return -1;
  }
  struct stat st {};
  if (::fstat(fd, &st) != 0) {
    why = errno_text(errno);
    ::close(fd);
    return -1;
  }
  if (!S_ISREG(st.st_mode)) {
    why = "is " + kind_of(st.st_mode) + ", not a regular file";
    ::close(fd);
    return -1;
  }
  if (static_cast<unsigned long long>(st.st_size) > max_bytes) {
    why = "is " + std::to_string(static_cast<long long>(st.st_size)) + " bytes, more than the " +
          std::to_string(max_bytes) + " bytes accepted";
    ::close(fd);
    return -1;
  }
  const int flags = ::fcntl(fd, F_GETFL);
  if (flags >= 0) ::fcntl(fd, F_SETFL, flags & ~O_NONBLOCK);
  return fd;
}

std::string read_error(int e) { return "read failed: " + errno_text(e); }

}  // namespace internal

bool read_input_file(const std::string& path, std::string& bytes, std::string& why,
                     std::size_t max_bytes) {
  bytes.clear();
  const int fd = internal::open_input_file(path, why, max_bytes);
  if (fd < 0) return false;
  struct stat st {};
  if (::fstat(fd, &st) != 0) st.st_size = 0;
  // The slack past the end lets a parser that reads ahead (simdjson) take the bytes in place.
  bytes.reserve(static_cast<std::size_t>(st.st_size) + kReadSlack);
  bytes.resize(static_cast<std::size_t>(st.st_size));
  std::size_t done = 0;
  while (true) {
    if (done == bytes.size()) {
      // The file may have grown since fstat; read what is there, within the limit.
      if (bytes.size() >= max_bytes) break;
      bytes.resize(std::min(max_bytes, bytes.size() + 65536));
    }
    const ssize_t n = ::read(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      why = internal::read_error(errno);
      ::close(fd);
      bytes.clear();
      return false;
    }
    if (n == 0) break;
    done += static_cast<std::size_t>(n);
  }
  bytes.resize(done);
  ::close(fd);
  return true;
}

void check_output_path(const std::string& path, const std::vector<std::string>& inputs,
                       const char* what, const std::vector<std::string>& outputs) {
  const std::string key = canonical_path(checked_target(path, inputs, what));
  for (const std::string& other : outputs) {
    std::string why;
    if (!other.empty() && canonical_path(resolve_links(other, why)) == key)
      refuse(what, path, "is also the output '" + other + "'; each output needs its own file");
  }
}

std::string canonical_path(const std::string& path) {
  std::error_code ec;
  const std::filesystem::path abs = std::filesystem::absolute(path, ec);
  if (ec) return path;
  const std::filesystem::path p = std::filesystem::weakly_canonical(abs, ec);
  return (ec ? abs : p).lexically_normal().string();
}

void write_outputs(const std::vector<OutputFile>& files, const std::vector<std::string>& inputs,
                   const char* what) {
  std::vector<StreamedOutput> streamed;
  for (const OutputFile& f : files)
    streamed.push_back(
        {f.path, [&f](const ByteSink& sink) { sink(f.bytes.data(), f.bytes.size()); }});
  write_streamed_outputs(streamed, inputs, what);
}

void write_streamed_outputs(const std::vector<StreamedOutput>& files,
                            const std::vector<std::string>& inputs, const char* what) {
  std::vector<std::string> targets, keys;
  for (const StreamedOutput& f : files) {
    targets.push_back(checked_target(f.path, inputs, what));
    keys.push_back(canonical_path(targets.back()));
    for (std::size_t k = 0; k + 1 < keys.size(); ++k)
      if (keys[k] == keys.back())
        refuse(what, f.path,
               "is also the output '" + files[k].path + "'; each output needs its own file");
  }
  std::vector<std::string> temps;
  std::vector<int> slots;
  const SignalCleanup cleanup;
  auto discard = [&temps] {
    for (const std::string& t : temps) ::unlink(t.c_str());
  };
  // Slots free again when this function returns, whichever way.
  struct Release {
    std::vector<int>& slots;
    ~Release() {
      for (int k : slots) SignalCleanup::remove(k);
    }
  } release{slots};
  const mode_t mask = ::umask(0);
  ::umask(mask);
  for (std::size_t i = 0; i < files.size(); ++i) {
    const std::string& target = targets[i];
    std::string tmp = temp_name(target);
    const int fd = ::mkstemp(tmp.data());
    if (fd < 0) {
      const int e = errno;
      discard();
      refuse(what, files[i].path,
             "cannot create a temporary file in '" + dir_of(target) + "': " + errno_text(e));
    }
    temps.push_back(tmp);
    slots.push_back(SignalCleanup::add(tmp));
    int err = 0;
    // After a failed write the rest of the bytes are dropped; the error is reported below.
    const ByteSink sink = [fd, &err](const char* data, std::size_t size) {
      std::size_t done = 0;
      while (err == 0 && done < size) {
        const ssize_t n = ::write(fd, data + done, size - done);
        if (n < 0) {
          if (errno != EINTR) err = errno;
          continue;
        }
        done += static_cast<std::size_t>(n);
      }
    };
    try {
      files[i].produce(sink);
    } catch (...) {
      ::close(fd);
      discard();
      throw;
    }
    if (err == 0 && ::fsync(fd) != 0) err = errno;
    // An existing target keeps its permissions; a new file gets the usual 0666 & ~umask
    // (mkstemp creates it 0600).
    struct stat st {};
    const mode_t mode = ::stat(target.c_str(), &st) == 0 ? (st.st_mode & 07777) : (0666 & ~mask);
    if (err == 0 && ::fchmod(fd, mode) != 0) err = errno;
    if (::close(fd) != 0 && err == 0) err = errno;
    if (err != 0) {
      discard();
      refuse(what, files[i].path, "write failed: " + errno_text(err));
    }
  }
  for (std::size_t i = 0; i < files.size(); ++i) {
    if (std::rename(temps[i].c_str(), targets[i].c_str()) != 0) {
      const int e = errno;
      for (std::size_t k = i; k < temps.size(); ++k) ::unlink(temps[k].c_str());
      refuse(what, files[i].path, "cannot rename the temporary file into place: " + errno_text(e));
    }
  }
}

std::string printable(const std::string& text, std::size_t max) {
  std::string out;
  const std::size_t n = std::min(text.size(), max);
  for (std::size_t i = 0; i < n; ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c >= 0x20 && c < 0x7f && c != '\\') {
      out += static_cast<char>(c);
    } else {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02X", c);
      out += buf;
    }
  }
  if (text.size() > max) out += "...";
  return out;
}

std::string quaternion_problem(double w, double x, double y, double z) {
  const double norm = std::sqrt(w * w + x * x + y * y + z * z);
  if (std::isfinite(norm) && std::abs(norm - 1) <= kUnitQuaternionTolerance) return {};
  char buf[160];
  std::snprintf(buf, sizeof buf, "the quaternion (qw,qx,qy,qz) has norm %.9g, not 1 within %g",
                norm, kUnitQuaternionTolerance);
  return buf;
}

std::string size_warning(const Polyhedron& model, const std::string& which, double epsilon_mm) {
  if (model.num_vertices() == 0 || !(epsilon_mm > 0)) return {};
  const double diag = (model.bbox_max() - model.bbox_min()).norm();
  const bool small = diag<kSmallModel * epsilon_mm, large = diag> kLargeModel * epsilon_mm;
  if (!small && !large) return {};
  char buf[160];
  std::snprintf(buf, sizeof buf,
                " is %.4g mm across (bounding-box diagonal), %s against the contact threshold "
                "epsilon = %g mm (%s %g epsilon)",
                diag, small ? "small" : "large", epsilon_mm, small ? "below" : "above",
                small ? kSmallModel : kLargeModel);
  return "model " + (which.empty() ? "" : which + " ") + "'" + printable(model.name(), 40) + "'" +
         buf;
}

}  // namespace cf
