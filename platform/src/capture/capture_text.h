// Text pieces of capture format v1: TUM list parsing with file:line errors, exact number
// formatting (shortest round-trip), and write-then-rename text files.
#pragma once
#include <string>
#include <string_view>
#include <vector>

#include "mrgi/expected.h"

namespace mrgi::capture {

// One non-comment line of a TUM list: its timestamp and the fields after it.
struct ListLine {
  int line = 0;                     // 1-based line number in the file
  double timestamp = 0.0;
  std::vector<std::string> fields;  // after the timestamp
};

// Reads a TUM-style list: '#' comments and blank lines are skipped; every other line must hold a
// finite timestamp followed by between min_fields and max_fields fields, and timestamps must
// strictly increase. `format` names the expected layout for messages ("timestamp path").
Expected<std::vector<ListLine>> read_list(const std::string& path, size_t min_fields, size_t max_fields,
                                          const char* format);

// Parses a whole token as a finite double; false otherwise.
bool parse_double(std::string_view token, double* out);

// Shortest decimal text that reads back to exactly the same double.
std::string format_double(double v);

// Writes TEXT to PATH.tmp and renames it to PATH.
Status write_text(const std::string& path, const std::string& text);

bool file_exists(const std::string& path);

}  // namespace mrgi::capture
