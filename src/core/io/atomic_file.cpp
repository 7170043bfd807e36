// Atomic file writes: every file the project writes goes through write_file_atomic.
#include "core/io/atomic_file.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>

#include "core/exec/error.h"

namespace wb {

namespace {
// Temporary files of saves to `target` whose process is gone (killed mid-save: it could not
// remove its own) are removed by the next save. Their names carry the writer's process id:
// `.NAME.tmp-PID-XXXXXX`; a file of a process still running (a concurrent save) is kept.
void remove_stale_temporaries(const std::filesystem::path& dir, const std::string& prefix) {
  std::error_code ec;
  for (std::filesystem::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.compare(0, prefix.size(), prefix) != 0) continue;
    const std::string rest = name.substr(prefix.size());
    const size_t dash = rest.find('-');
    if (dash == 0 || dash == std::string::npos || rest.size() != dash + 7) continue;
    if (rest.find_first_not_of("0123456789") != dash) continue;
    const long pid = std::strtol(rest.c_str(), nullptr, 10);
    if (pid <= 0 || pid == long(::getpid())) continue;
    if (::kill(pid_t(pid), 0) != 0 && errno == ESRCH) ::unlink(it->path().c_str());
  }
}
}  // namespace

void write_file_atomic(const std::string& path, const void* data, size_t size,
                       const std::function<void(const std::string&)>& hook) {
  const auto* bytes = static_cast<const uint8_t*>(data);
  namespace fs = std::filesystem;
  const fs::path target(path);
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  std::string prefix = ".";  // appended, not "." + string&&: GCC 12 warns falsely (-Wrestrict) on that
  prefix += target.filename().string();
  prefix += ".tmp-";
  remove_stale_temporaries(dir, prefix);
  std::string tmpl = (dir / (prefix + std::to_string(::getpid()) + "-XXXXXX")).string();
  int fd = mkstemp(tmpl.data());
  if (fd < 0) WB_THROW(path + ": cannot create a temporary file in " + dir.string() + ": " + std::strerror(errno));
  const std::string tmp = tmpl;
  // Whatever goes wrong before the rename, the temporary file goes and `path` is untouched.
  try {
    size_t done = 0;
    const size_t half = size / 2;
    bool hooked = false;
    while (done < size) {
      const size_t limit = hooked ? size : std::max<size_t>(half, 1);
      const ssize_t n = ::write(fd, bytes + done, std::min(size, limit) - done);
      if (n < 0) {
        if (errno == EINTR) continue;
        WB_THROW(path + ": save failed: write: " + std::strerror(errno));
      }
      done += size_t(n);
      if (!hooked && done >= half) {
        hooked = true;
        if (hook) hook("partial-write");
      }
    }
    if (::fsync(fd) != 0) WB_THROW(path + ": save failed: fsync: " + std::strerror(errno));
    const int rc = ::close(fd);
    fd = -1;
    if (rc != 0) WB_THROW(path + ": save failed: close: " + std::strerror(errno));
    ::chmod(tmp.c_str(), 0644);
    if (hook) hook("before-rename");
    if (::rename(tmp.c_str(), path.c_str()) != 0) WB_THROW(path + ": save failed: rename: " + std::strerror(errno));
  } catch (...) {
    if (fd >= 0) ::close(fd);
    ::unlink(tmp.c_str());
    throw;
  }
  const int dfd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY);
  if (dfd >= 0) {
    ::fsync(dfd);  // makes the rename durable; a failure here cannot undo it, so it is not an error
    ::close(dfd);
  }
}

void write_file_atomic(const std::string& path, const std::vector<uint8_t>& bytes,
                       const std::function<void(const std::string&)>& fault_hook) {
  write_file_atomic(path, bytes.data(), bytes.size(), fault_hook);
}

void write_file_atomic(const std::string& path, const std::string& text) {
  write_file_atomic(path, text.data(), text.size());
}

}  // namespace wb
