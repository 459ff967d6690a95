// Test helper: the text of a file under examples/ (INBETWEEN_SOURCE_DIR is set by CMake).
#pragma once

#include <cstdio>
#include <string>

namespace inbetween::solver {

inline std::string ReadExample(const std::string& relative_path) {
  const std::string path = std::string(INBETWEEN_SOURCE_DIR) + "/examples/" + relative_path;
  std::string text;
  if (FILE* f = std::fopen(path.c_str(), "rb")) {
    char buffer[4096];
    for (size_t n; (n = std::fread(buffer, 1, sizeof buffer, f)) > 0;) text.append(buffer, n);
    std::fclose(f);
  }
  return text;
}

}  // namespace inbetween::solver
