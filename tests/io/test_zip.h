// Test helpers for painting files: a ZIP archive built entry by entry in memory, for the
// fixtures other programs, damage or hostile files would produce.
#pragma once
#include <zip.h>

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace wb::test {

/// Entries in order, each stored (`deflate` false) or deflated.
inline std::vector<uint8_t> make_zip(const std::vector<std::pair<std::string, std::vector<uint8_t>>>& entries,
                                     bool deflate = false) {
  zip_error_t ze;
  zip_error_init(&ze);
  zip_source_t* src = zip_source_buffer_create(nullptr, 0, 0, &ze);
  zip_source_keep(src);
  zip_t* za = zip_open_from_source(src, ZIP_TRUNCATE, &ze);
  for (const auto& [name, data] : entries) {
    zip_source_t* s = zip_source_buffer(za, data.data(), data.size(), 0);
    const zip_int64_t i = zip_file_add(za, name.c_str(), s, ZIP_FL_ENC_UTF_8);
    zip_set_file_compression(za, zip_uint64_t(i), deflate && name != "mimetype" ? ZIP_CM_DEFLATE : ZIP_CM_STORE, 1);
  }
  zip_close(za);
  zip_stat_t st;
  zip_source_stat(src, &st);
  zip_source_open(src);
  std::vector<uint8_t> out(size_t(st.size));
  zip_source_read(src, out.data(), out.size());
  zip_source_close(src);
  zip_source_free(src);
  return out;
}

inline std::vector<uint8_t> bytes_of(const std::string& s) { return {s.begin(), s.end()}; }

}  // namespace wb::test
