#include "icef/io/atomic_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>

#include "icef/core/rng.h"

namespace icef {

namespace fs = std::filesystem;

Status WriteFileAtomic(const fs::path& path, std::string_view bytes) {
  const fs::path dir = path.has_parent_path() ? path.parent_path() : fs::path(".");
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    return Status::Error(path.string() + ": directory " + dir.string() + " does not exist");
  // A unique temporary name beside the destination (same filesystem, so rename is atomic).
  const uint64_t tag = Mix64(static_cast<uint64_t>(getpid()) ^ reinterpret_cast<uintptr_t>(&bytes) ^
                             static_cast<uint64_t>(bytes.size()));
  char suffix[32];
  std::snprintf(suffix, sizeof suffix, ".tmp.%012llx",
                static_cast<unsigned long long>(tag & 0xffffffffffffULL));
  const fs::path tmp = dir / (path.filename().string() + suffix);
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) return Status::Error(path.string() + ": cannot create temporary file: " + std::strerror(errno));
  size_t written = 0;
  while (written < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + written, bytes.size() - written);
    if (n < 0) {
      if (errno == EINTR) continue;
      const std::string why = std::strerror(errno);
      ::close(fd);
      fs::remove(tmp, ec);
      return Status::Error(path.string() + ": write failed: " + why);
    }
    written += static_cast<size_t>(n);
  }
  if (::fsync(fd) != 0 || ::close(fd) != 0) {
    const std::string why = std::strerror(errno);
    fs::remove(tmp, ec);
    return Status::Error(path.string() + ": flush failed: " + why);
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    const std::string why = std::strerror(errno);
    fs::remove(tmp, ec);
    return Status::Error(path.string() + ": rename failed: " + why);
  }
  return Status::Ok();
}

Status CreateDirectoryAtomic(const fs::path& dir, const std::function<Status(const fs::path& tmp)>& fill) {
  std::error_code ec;
  if (fs::exists(dir, ec) && !(fs::is_directory(dir, ec) && fs::is_empty(dir, ec)))
    return Status::Error(dir.string() + ": already exists and is not an empty directory");
  const fs::path parent = dir.has_parent_path() ? dir.parent_path() : fs::path(".");
  const fs::path tmp = parent / (dir.filename().string() + ".tmp-" + std::to_string(getpid()));
  fs::remove_all(tmp, ec);
  if (!fs::create_directories(tmp, ec))
    return Status::Error(tmp.string() + ": cannot create the directory: " + ec.message());
  Status status = fill(tmp);
  if (status.ok()) {
    if (fs::exists(dir, ec)) fs::remove(dir, ec);  // an empty directory
    fs::rename(tmp, dir, ec);
    if (ec)
      status = Status::Error(dir.string() + ": cannot move the new directory into place: " + ec.message());
  }
  if (!status.ok()) fs::remove_all(tmp, ec);
  return status;
}

Result<std::string> ReadFile(const fs::path& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) return Status::Error(path.string() + ": file not found");
  if (fs::is_directory(path, ec)) return Status::Error(path.string() + ": is a directory, expected a file");
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::Error(path.string() + ": cannot open for reading");
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) return Status::Error(path.string() + ": read error");
  return ss.str();
}

}  // namespace icef
