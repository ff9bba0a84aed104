// Atomic file replacement: write a temporary file next to the target, fsync, rename over it.
#include "posefair/formats/atomic_write.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>

#include "posefair/formats/pose_file.hpp"

namespace posefair::formats {

namespace {

// Closes and removes the temporary file unless released.
class TempFile {
 public:
  TempFile(std::string path, int fd) : path_(std::move(path)), fd_(fd) {}
  TempFile(const TempFile&) = delete;
  TempFile& operator=(const TempFile&) = delete;
  ~TempFile() {
    if (fd_ >= 0) ::close(fd_);
    if (!released_) ::unlink(path_.c_str());
  }
  int fd() const { return fd_; }
  int close() {
    const int rc = ::close(fd_);
    fd_ = -1;
    return rc;
  }
  void release() { released_ = true; }

 private:
  std::string path_;
  int fd_;
  bool released_ = false;
};

[[noreturn]] void fail(const std::filesystem::path& path, const std::string& what, int error) {
  throw PoseFileError(path.string(), 0, what + ": " + std::strerror(error));
}

}  // namespace

void write_file_atomically(const std::filesystem::path& path, std::string_view contents) {
  const std::string target = path.string();
  const std::string tmp = target + ".tmp." + std::to_string(::getpid());

  int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  if (fd < 0 && errno == EEXIST) {
    // Left over by an earlier process that had our pid and died mid-write.
    ::unlink(tmp.c_str());
    fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  }
  if (fd < 0) fail(path, "cannot create temporary file '" + tmp + "'", errno);
  TempFile file(tmp, fd);

  // Keep the permission bits of the file being replaced.
  struct stat st{};
  if (::stat(target.c_str(), &st) == 0) {
    if (!S_ISREG(st.st_mode)) fail(path, "not a regular file", EINVAL);
    if (::fchmod(fd, st.st_mode & 07777) != 0) fail(path, "cannot set permissions", errno);
  }

  const char* data = contents.data();
  std::size_t left = contents.size();
  while (left > 0) {
    const ssize_t n = ::write(fd, data, left);
    if (n < 0) {
      if (errno == EINTR) continue;
      fail(path, "cannot write '" + tmp + "'", errno);
    }
    data += n;
    left -= static_cast<std::size_t>(n);
  }
  if (::fsync(fd) != 0) fail(path, "cannot fsync '" + tmp + "'", errno);
  if (file.close() != 0) fail(path, "cannot close '" + tmp + "'", errno);
  if (::rename(tmp.c_str(), target.c_str()) != 0) fail(path, "cannot rename over the file", errno);
  file.release();

  // Make the rename itself durable; the new file is complete either way, so this is best effort.
  std::filesystem::path dir = path.parent_path();
  if (dir.empty()) dir = ".";
  const int dfd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dfd >= 0) {
    (void)::fsync(dfd);
    ::close(dfd);
  }
}

}  // namespace posefair::formats
