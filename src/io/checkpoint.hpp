// Binary checkpoints: a versioned file of tagged sections (tag, element size, count, raw
// bytes) closed by a checksum. Sections are read back by tag, in any order; every problem
// (missing tag, element-size mismatch, truncation, corruption, wrong magic or version) is an
// ff::InputError naming the file and, where relevant, the tag. Written atomically: a run killed
// while checkpointing leaves the previous checkpoint intact.
//
// Layout (little-endian): "FFCHKPT\0", u32 format version, u32 0; per section: u32 tag length,
// tag, u32 element size, u64 count, count*size bytes; then u32 0xFFFFFFFF, u64 number of
// sections, u64 checksum of every byte before it.
#pragma once
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "core/types.hpp"

namespace ff {

class AtomicFileWriter;

namespace detail {
// 64-bit checksum of a byte stream, fed in pieces of any size (word-wise FNV-1a style mix).
struct Checksum {
  std::uint64_t h = 0xcbf29ce484222325ull, total = 0;
  unsigned char pending[8] = {};
  std::size_t npending = 0;
  void update(const void* p, std::size_t n);  // feeds n more bytes
  std::uint64_t value() const;                // checksum of everything fed so far
};
}  // namespace detail

// 2: parallel-bond state holds loads only; 3: the UCS lateral gauge, the triaxial isotropic-stage
// counter and the flexible membrane's contact history are stored instead of re-derived at resume;
// 4: particle global ids (dem.id, dem.next_id), crack events name particles by global id, no
// dem.inward_force (the particle membrane's loads come from its layout at resume).
inline constexpr std::uint32_t kCheckpointFormatVersion = 4;

// Types stored as raw bytes: trivially copyable ones, plus Eigen fixed-size vectors/matrices and
// quaternions of arithmetic scalars (memcpy-safe though Eigen declares copy constructors).
template <class T> struct is_checkpoint_pod : std::bool_constant<std::is_trivially_copyable_v<T> && !std::is_pointer_v<T>> {};
template <class S, int R, int C, int O, int MR, int MC>
struct is_checkpoint_pod<Eigen::Matrix<S, R, C, O, MR, MC>> : std::bool_constant<(R > 0 && C > 0 && std::is_arithmetic_v<S>)> {};
template <class S, int O> struct is_checkpoint_pod<Eigen::Quaternion<S, O>> : std::is_arithmetic<S> {};

class CheckpointWriter {
 public:
  // Starts writing `path` (via a temporary file; nothing replaces `path` before commit()).
  // With keep_previous, commit() first keeps the file it replaces as
  // previous_checkpoint_path(path), so a complete checkpoint exists at every instant.
  explicit CheckpointWriter(std::filesystem::path path, bool keep_previous = false);
  ~CheckpointWriter();  // without commit(): the temporary file is removed, `path` untouched

  // Stores a vector as one section; T must satisfy is_checkpoint_pod.
  template <class T> void put(std::string_view tag, const std::vector<T>& v) {
    check_type<T>();
    put_bytes(tag, sizeof(T), v.size(), v.data());
  }
  // Stores one value as a section of count 1.
  template <class T> void put_value(std::string_view tag, const T& v) {
    check_type<T>();
    put_bytes(tag, sizeof(T), 1, &v);
  }
  void put_string(std::string_view tag, const std::string& s);  // stores text (element size 1)
  void commit();  // writes the end marker and checksum, fsyncs, renames into place

 private:
  template <class T> static constexpr void check_type() {
    static_assert(is_checkpoint_pod<T>::value, "checkpoint sections hold trivially copyable types (or Eigen fixed-size types)");
  }
  void put_bytes(std::string_view tag, std::size_t elem_size, std::size_t count, const void* data);
  void hashed_write(const void* p, std::size_t n);
  std::unique_ptr<AtomicFileWriter> out_;
  std::vector<std::string> tags_;
  detail::Checksum sum_;
};

class CheckpointReader {
 public:
  // Opens and verifies the whole file (magic, version, checksum, section table).
  explicit CheckpointReader(std::filesystem::path path);

  // Reads section `tag` into v (resized); throws if missing or the element size differs.
  template <class T> void get(std::string_view tag, std::vector<T>& v) {
    static_assert(is_checkpoint_pod<T>::value, "checkpoint sections hold trivially copyable types (or Eigen fixed-size types)");
    v.resize(count(tag, sizeof(T)));
    read(tag, v.data());
  }
  // Reads a section written with put_value; throws unless it holds exactly one T.
  template <class T> T get_value(std::string_view tag) {
    static_assert(is_checkpoint_pod<T>::value, "checkpoint sections hold trivially copyable types (or Eigen fixed-size types)");
    T v{};
    if (count(tag, sizeof(T)) != 1) fail_count(tag);
    read(tag, &v);
    return v;
  }
  std::string get_string(std::string_view tag);  // reads a section written with put_string
  bool has(std::string_view tag) const;          // section exists
  std::vector<std::string> tags() const;         // all section tags, sorted
  const std::filesystem::path& path() const { return path_; }  // the file

 private:
  struct Section {
    std::uint64_t offset, elem_size, count;
  };
  const Section& find(std::string_view tag) const;
  std::size_t count(std::string_view tag, std::size_t elem_size) const;  // checks the element size
  void read(std::string_view tag, void* out);
  [[noreturn]] void fail_count(std::string_view tag) const;
  std::filesystem::path path_;
  std::ifstream in_;
  std::map<std::string, Section, std::less<>> sections_;
};

// The older checkpoint kept beside `newest` ("state.ffcp" -> "state.prev.ffcp").
std::filesystem::path previous_checkpoint_path(const std::filesystem::path& newest);
// Opens `newest`; when it is missing, truncated or fails its checksum, opens the previous one
// kept beside it instead, with a warning naming both. Throws InputError naming both (and why)
// when neither can be read.
CheckpointReader open_checkpoint(const std::filesystem::path& newest);

}  // namespace ff
