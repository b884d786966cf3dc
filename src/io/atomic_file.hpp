// Files that appear whole or not at all: everything is written to `path.tmp.<pid>` and then
// renamed over `path` (rename(2) is atomic on POSIX), so a run killed mid-write never leaves
// a half-written snapshot, checkpoint or summary for ParaView or a restart to trip over.
#pragma once
#include <cstdio>
#include <filesystem>
#include <string_view>

namespace ff {

// Writes `bytes` to `path` atomically; creates parent folders; throws ff::Error naming the path.
void write_file_atomic(const std::filesystem::path& path, std::string_view bytes);
// Same, and fsyncs the data before the rename and the folder after it when `durable` (survives
// a power loss, slower).
void write_file_atomic(const std::filesystem::path& path, std::string_view bytes, bool durable);

// Streaming form for large files (checkpoints): write() appends to the temporary file,
// commit() renames it into place. Destroyed without commit() it removes the temporary file.
class AtomicFileWriter {
 public:
  // Opens `path.tmp.<pid>` (creating parent folders); throws ff::Error naming the path.
  explicit AtomicFileWriter(std::filesystem::path path, bool durable = false);
  ~AtomicFileWriter();
  AtomicFileWriter(const AtomicFileWriter&) = delete;
  AtomicFileWriter& operator=(const AtomicFileWriter&) = delete;

  void write(const void* data, std::size_t n);  // appends n bytes; throws ff::Error on failure
  void write(std::string_view s) { write(s.data(), s.size()); }  // appends a string's bytes
  void commit();                                 // flushes, (fsyncs,) renames onto the final path
  // Before commit() replaces the final file, keep the file it replaces as `previous` (itself
  // replaced atomically), so a complete older copy exists at every instant.
  void keep_previous_as(std::filesystem::path previous) { previous_ = std::move(previous); }
  std::size_t bytes_written() const { return written_; }  // bytes appended so far
  const std::filesystem::path& path() const { return path_; }  // final destination

 private:
  [[noreturn]] void fail(const char* what);
  std::filesystem::path path_, tmp_, previous_;
  std::FILE* f_ = nullptr;
  bool durable_ = false;
  std::size_t written_ = 0;
};

}  // namespace ff
