#include "io/json_out.hpp"

#include "io/atomic_file.hpp"

namespace ff {

void write_json_atomic(const std::filesystem::path& path, const nlohmann::json& j) {
  // nlohmann::json serialises non-finite numbers as null (JSON has no NaN); `replace` keeps a
  // stray non-UTF-8 byte in a string from throwing while a run's summary is written.
  std::string text = j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace);
  text += '\n';
  write_file_atomic(path, text);
}

}  // namespace ff
