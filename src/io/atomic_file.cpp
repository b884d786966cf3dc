#include "io/atomic_file.hpp"

#include <fmt/format.h>
#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <system_error>

#include "core/error.hpp"

namespace ff {

AtomicFileWriter::AtomicFileWriter(std::filesystem::path path, bool durable) : path_(std::move(path)), durable_(durable) {
  if (path_.empty()) throw Error("cannot write a file with an empty path");
  const auto parent = path_.parent_path();
  if (!parent.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(parent, ec);
    if (ec) throw Error(fmt::format("cannot write '{}': cannot create folder '{}': {}", path_.string(), parent.string(), ec.message()));
  }
  tmp_ = path_;
  tmp_ += fmt::format(".tmp.{}", static_cast<long>(::getpid()));
  f_ = std::fopen(tmp_.c_str(), "wb");
  if (!f_) fail("cannot create the temporary file");
}

AtomicFileWriter::~AtomicFileWriter() {
  if (f_) {  // not committed: leave the previous file (if any) untouched
    std::fclose(f_);
    std::error_code ec;
    std::filesystem::remove(tmp_, ec);
  }
}

void AtomicFileWriter::fail(const char* what) {
  const int err = errno;
  if (f_) {
    std::fclose(f_);
    f_ = nullptr;
  }
  std::error_code ec;
  std::filesystem::remove(tmp_, ec);
  throw Error(fmt::format("cannot write '{}': {} ({})", path_.string(), what, std::strerror(err)));
}

void AtomicFileWriter::write(const void* data, std::size_t n) {
  if (!f_) throw Error(fmt::format("internal: write to '{}' after commit", path_.string()));
  if (n > 0 && std::fwrite(data, 1, n, f_) != n) fail("write failed (disk full?)");
  written_ += n;
}

void AtomicFileWriter::commit() {
  if (!f_) throw Error(fmt::format("internal: '{}' committed twice", path_.string()));
  if (std::fflush(f_) != 0) fail("write failed (disk full?)");
  if (durable_ && ::fsync(::fileno(f_)) != 0) fail("fsync failed");
  if (std::fclose(f_) != 0) {
    f_ = nullptr;
    fail("close failed (disk full?)");
  }
  f_ = nullptr;
  if (!previous_.empty() && ::access(path_.c_str(), F_OK) == 0) {
    // A hard link keeps `path_` in place until the new file replaces it; without hard links
    // (some network file systems) a rename leaves the older copy alone for an instant.
    auto prev_tmp = previous_;
    prev_tmp += fmt::format(".tmp.{}", static_cast<long>(::getpid()));
    ::unlink(prev_tmp.c_str());
    const bool kept = ::link(path_.c_str(), prev_tmp.c_str()) == 0 ? std::rename(prev_tmp.c_str(), previous_.c_str()) == 0
                                                                   : std::rename(path_.c_str(), previous_.c_str()) == 0;
    if (!kept) {
      const int err = errno;
      ::unlink(prev_tmp.c_str());
      std::error_code ec;
      std::filesystem::remove(tmp_, ec);
      throw Error(fmt::format("cannot write '{}': keeping the previous copy as '{}' failed ({})", path_.string(),
                              previous_.string(), std::strerror(err)));
    }
  }
  if (std::rename(tmp_.c_str(), path_.c_str()) != 0) {
    const int err = errno;
    std::error_code ec;
    std::filesystem::remove(tmp_, ec);
    throw Error(fmt::format("cannot write '{}': renaming the temporary file failed ({})", path_.string(), std::strerror(err)));
  }
  if (durable_) {  // the renames themselves survive a power loss only once the folder is synced
    const auto dir = path_.has_parent_path() ? path_.parent_path() : std::filesystem::path(".");
    const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY);
    if (fd >= 0) {
      ::fsync(fd);
      ::close(fd);
    }
  }
}

void write_file_atomic(const std::filesystem::path& path, std::string_view bytes, bool durable) {
  AtomicFileWriter w(path, durable);
  w.write(bytes);
  w.commit();
}

void write_file_atomic(const std::filesystem::path& path, std::string_view bytes) { write_file_atomic(path, bytes, false); }

}  // namespace ff
