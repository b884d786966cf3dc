#include "io/checkpoint.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cstring>

#include "core/error.hpp"
#include "core/log.hpp"
#include "io/atomic_file.hpp"

namespace ff {

namespace {
constexpr char kMagic[8] = {'F', 'F', 'C', 'H', 'K', 'P', 'T', '\0'};
constexpr std::uint32_t kEndMarker = 0xFFFFFFFFu;
constexpr std::size_t kHeaderBytes = 16, kTrailerBytes = 4 + 8 + 8, kMaxTag = 4096;
constexpr std::uint64_t kPrime = 0x100000001b3ull;
// Advice when a checkpoint cannot be used: the commands that exist (there is no --resume flag).
constexpr const char* kStartOver = "to start the run again from the beginning: fracflow run SCENARIO --out DIR --overwrite";
}  // namespace

// ---------------------------------------------------------------- checksum

void detail::Checksum::update(const void* p, std::size_t n) {
  auto* b = static_cast<const unsigned char*>(p);
  total += n;
  auto mix = [this](const unsigned char* w) {
    std::uint64_t x;
    std::memcpy(&x, w, 8);
    h = (h ^ x) * kPrime;
    h ^= h >> 32;
  };
  if (npending > 0) {  // complete the partial word left by the previous call first
    const std::size_t take = std::min(n, sizeof pending - npending);
    std::memcpy(pending + npending, b, take);
    npending += take;
    b += take;
    n -= take;
    if (npending < sizeof pending) return;
    mix(pending);
    npending = 0;
  }
  for (; n >= 8; n -= 8, b += 8) mix(b);
  if (n > 0) std::memcpy(pending, b, n);
  npending = n;
}

std::uint64_t detail::Checksum::value() const {
  std::uint64_t v = h;
  for (std::size_t i = 0; i < npending; ++i) v = (v ^ pending[i]) * kPrime;
  return (v ^ total) * kPrime;
}

// ---------------------------------------------------------------- writer

CheckpointWriter::CheckpointWriter(std::filesystem::path path, bool keep_previous)
    : out_(std::make_unique<AtomicFileWriter>(path, /*durable=*/true)) {
  if (keep_previous) out_->keep_previous_as(previous_checkpoint_path(path));
  const std::uint32_t version = kCheckpointFormatVersion, zero = 0;
  hashed_write(kMagic, sizeof kMagic);
  hashed_write(&version, 4);
  hashed_write(&zero, 4);
}

CheckpointWriter::~CheckpointWriter() = default;

void CheckpointWriter::hashed_write(const void* p, std::size_t n) {
  if (!out_) throw Error("internal: checkpoint written after commit()");
  out_->write(p, n);
  sum_.update(p, n);
}

void CheckpointWriter::put_bytes(std::string_view tag, std::size_t elem_size, std::size_t count, const void* data) {
  if (!out_) throw Error(fmt::format("internal: checkpoint section '{}' written after commit()", tag));
  if (tag.empty() || tag.size() > kMaxTag) throw Error(fmt::format("internal: checkpoint tag '{}' is empty or too long", tag));
  if (std::find(tags_.begin(), tags_.end(), tag) != tags_.end())
    throw Error(fmt::format("internal: checkpoint '{}': section '{}' written twice", out_->path().string(), tag));
  tags_.emplace_back(tag);
  const auto tag_len = static_cast<std::uint32_t>(tag.size()), es = static_cast<std::uint32_t>(elem_size);
  const auto n = static_cast<std::uint64_t>(count);
  hashed_write(&tag_len, 4);
  hashed_write(tag.data(), tag.size());
  hashed_write(&es, 4);
  hashed_write(&n, 8);
  if (count > 0) hashed_write(data, elem_size * count);
}

void CheckpointWriter::put_string(std::string_view tag, const std::string& s) { put_bytes(tag, 1, s.size(), s.data()); }

void CheckpointWriter::commit() {
  if (!out_) throw Error("internal: checkpoint committed twice");
  const std::uint64_t n = tags_.size();
  hashed_write(&kEndMarker, 4);
  hashed_write(&n, 8);
  const std::uint64_t sum = sum_.value();
  out_->write(&sum, 8);
  out_->commit();
  out_.reset();
}

// ---------------------------------------------------------------- reader

CheckpointReader::CheckpointReader(std::filesystem::path path) : path_(std::move(path)) {
  const std::string name = path_.string();
  in_.open(path_, std::ios::binary);
  if (!in_) throw InputError(fmt::format("cannot read checkpoint '{}': no such file or not readable", name));
  in_.seekg(0, std::ios::end);
  const auto size = static_cast<std::uint64_t>(in_.tellg());
  in_.seekg(0);
  auto truncated = [&](const std::string& why) {
    return InputError(fmt::format("checkpoint '{}' is truncated or corrupted ({}); {}", name, why, kStartOver));
  };
  char head[12] = {};
  in_.read(head, 12);
  const auto got = static_cast<std::size_t>(in_.gcount());
  in_.clear();
  if (std::memcmp(head, kMagic, std::min<std::size_t>(got, 8)) != 0 || got == 0)
    throw InputError(fmt::format("'{}' is not a fracflow checkpoint (wrong magic bytes)", name));
  if (got < 12) throw truncated(fmt::format("only {} bytes", size));
  std::uint32_t version = 0;
  std::memcpy(&version, head + 8, 4);
  if (version != kCheckpointFormatVersion)
    throw InputError(fmt::format("checkpoint '{}' has format version {}, this build reads version {}; resume it with the "
                                 "fracflow version that wrote it, or {}", name, version, kCheckpointFormatVersion, kStartOver));
  if (size < kHeaderBytes + kTrailerBytes) throw truncated(fmt::format("only {} bytes", size));

  // Verify the checksum over the whole file before trusting any section header.
  detail::Checksum sum;
  std::vector<char> buf(1 << 20);
  in_.seekg(0);
  for (std::uint64_t left = size - 8; left > 0;) {
    const std::size_t n = static_cast<std::size_t>(std::min<std::uint64_t>(left, buf.size()));
    if (!in_.read(buf.data(), static_cast<std::streamsize>(n))) throw truncated("read failed");
    sum.update(buf.data(), n);
    left -= n;
  }
  std::uint64_t stored = 0;
  in_.read(reinterpret_cast<char*>(&stored), 8);
  if (!in_ || stored != sum.value()) throw truncated("checksum mismatch");

  // Walk the section headers.
  const std::uint64_t end = size - kTrailerBytes;
  std::uint64_t pos = kHeaderBytes;
  auto read_at = [&](std::uint64_t at, void* out, std::size_t n) {
    in_.seekg(static_cast<std::streamoff>(at));
    if (!in_.read(static_cast<char*>(out), static_cast<std::streamsize>(n))) throw truncated("read failed");
  };
  while (pos < end) {
    std::uint32_t tag_len = 0, es = 0;
    std::uint64_t count = 0;
    if (end - pos < 4) throw truncated("section header cut short");
    read_at(pos, &tag_len, 4);
    if (tag_len == 0 || tag_len > kMaxTag || end - pos < 4ull + tag_len + 12) throw truncated("bad section header");
    std::string tag(tag_len, '\0');
    read_at(pos + 4, tag.data(), tag_len);
    read_at(pos + 4 + tag_len, &es, 4);
    read_at(pos + 8 + tag_len, &count, 8);
    const std::uint64_t data_at = pos + 16 + tag_len;
    if ((es == 0 && count > 0) || (es > 0 && count > (end - data_at) / es)) throw truncated(fmt::format("section '{}' too long", tag));
    if (!sections_.emplace(tag, Section{data_at, es, count}).second) throw truncated(fmt::format("section '{}' twice", tag));
    pos = data_at + es * count;
  }
  std::uint32_t marker = 0;
  std::uint64_t nsec = 0;
  read_at(end, &marker, 4);
  read_at(end + 4, &nsec, 8);
  if (marker != kEndMarker || nsec != sections_.size()) throw truncated("bad end marker");
}

const CheckpointReader::Section& CheckpointReader::find(std::string_view tag) const {
  auto it = sections_.find(tag);
  if (it == sections_.end()) {
    std::string known;
    for (auto& [k, s] : sections_) known += (known.empty() ? "" : ", ") + k;
    throw InputError(fmt::format("checkpoint '{}' has no section '{}' (it holds: {}); was it written by another driver "
                                 "or version?", path_.string(), tag, known));
  }
  return it->second;
}

std::size_t CheckpointReader::count(std::string_view tag, std::size_t elem_size) const {
  const Section& s = find(tag);
  if (s.elem_size != elem_size)
    throw InputError(fmt::format("checkpoint '{}': section '{}' holds elements of {} bytes, read as {} bytes; was it written "
                                 "by another version?", path_.string(), tag, s.elem_size, elem_size));
  return static_cast<std::size_t>(s.count);
}

void CheckpointReader::read(std::string_view tag, void* out) {
  const Section& s = find(tag);
  if (s.count == 0) return;
  in_.clear();
  in_.seekg(static_cast<std::streamoff>(s.offset));
  if (!in_.read(static_cast<char*>(out), static_cast<std::streamsize>(s.elem_size * s.count)))
    throw InputError(fmt::format("checkpoint '{}': reading section '{}' failed (file changed while reading?)", path_.string(), tag));
}

void CheckpointReader::fail_count(std::string_view tag) const {
  throw InputError(fmt::format("checkpoint '{}': section '{}' holds {} values, expected exactly one", path_.string(), tag,
                               find(tag).count));
}

std::string CheckpointReader::get_string(std::string_view tag) {
  std::string s(count(tag, 1), '\0');
  read(tag, s.data());
  return s;
}

bool CheckpointReader::has(std::string_view tag) const { return sections_.find(tag) != sections_.end(); }

std::vector<std::string> CheckpointReader::tags() const {
  std::vector<std::string> t;
  for (auto& [k, s] : sections_) t.push_back(k);
  return t;
}

// ---------------------------------------------------------------- rotation

std::filesystem::path previous_checkpoint_path(const std::filesystem::path& newest) {
  auto p = newest;
  p.replace_filename(newest.stem().string() + ".prev" + newest.extension().string());
  return p;
}

CheckpointReader open_checkpoint(const std::filesystem::path& newest) {
  const auto prev = previous_checkpoint_path(newest);
  try {
    return CheckpointReader(newest);
  } catch (const InputError& e) {
    if (!std::filesystem::exists(prev)) throw;
    const std::string why = e.what();
    try {
      CheckpointReader r(prev);
      log::warn("the newest checkpoint '{}' cannot be used ({}); resuming from the previous one, '{}'", newest.string(), why,
                prev.string());
      return r;
    } catch (const InputError& e2) {
      throw InputError(fmt::format("neither checkpoint can be used: '{}': {}; '{}': {}", newest.string(), why, prev.string(),
                                   e2.what()));
    }
  }
}

}  // namespace ff
