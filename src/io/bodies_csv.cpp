#include "collision_lab/io/bodies_csv.h"

#include <algorithm>
#include <fstream>
#include <iostream>
#include <string_view>

#include "collision_lab/io/number_text.h"

namespace collision_lab {
namespace io {

namespace {

constexpr std::string_view kHeader = "mass,position,velocity";
const char* const kColumns[3] = {"mass", "position", "velocity"};

std::string_view withoutCarriageReturn(std::string_view line) {
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  return line;
}

/// One body line -> its three values, appended to the scene.
void readBody(std::string_view line, std::size_t line_number, core::Scene& scene) {
  const std::string where = "bodies:" + std::to_string(line_number);
  std::string_view items[3];
  std::size_t count = 0, start = 0;
  for (;;) {
    const std::size_t comma = line.find(',', start);
    const std::string_view item = line.substr(start, comma == std::string_view::npos ? comma : comma - start);
    if (count < 3) items[count] = item;
    ++count;
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  if (count != 3) {
    throw BodiesFileError(BodiesFileError::Kind::kWrongCount, where,
                          "3 comma-separated numbers are needed (mass,position,velocity), got " +
                              std::to_string(count) + " in '" + std::string(line) + "'");
  }
  std::vector<double>* columns[3] = {&scene.masses, &scene.positions, &scene.velocities};
  for (std::size_t c = 0; c < 3; ++c) {
    const ParsedNumber parsed = parseNumber(items[c]);
    if (!parsed.problem.empty()) {
      throw BodiesFileError(BodiesFileError::Kind::kMalformedNumber, where + ":" + kColumns[c],
                            "'" + std::string(items[c]) + "' " + parsed.problem);
    }
    columns[c]->push_back(parsed.value);
  }
}

/// The whole stream, in chunks (standard input has no size to ask for).
std::string readAll(std::istream& in) {
  std::string text;
  std::vector<char> chunk(std::size_t{1} << 20);
  while (in.read(chunk.data(), static_cast<std::streamsize>(chunk.size())) || in.gcount() > 0) {
    text.append(chunk.data(), static_cast<std::size_t>(in.gcount()));
  }
  if (in.bad()) throw BodiesFileError(BodiesFileError::Kind::kUnreadable, "bodies", "cannot read the bodies file");
  return text;
}

}  // namespace

core::Scene readBodiesCsv(std::istream& in) {
  const std::string text = readAll(in);
  core::Scene scene;
  const std::size_t lines = static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n')) + 1;
  for (auto* column : {&scene.masses, &scene.positions, &scene.velocities}) column->reserve(lines);
  bool header_seen = false;
  std::size_t line_number = 0;
  for (std::size_t start = 0; start < text.size();) {
    const std::size_t end = std::min(text.find('\n', start), text.size());
    const std::string_view line = withoutCarriageReturn(std::string_view(text).substr(start, end - start));
    start = end + 1;
    ++line_number;
    if (line.empty() || line.front() == '#') continue;
    if (!header_seen) {
      if (line != kHeader) {
        throw BodiesFileError(BodiesFileError::Kind::kHeader, "bodies:" + std::to_string(line_number),
                              "the first line must be the header 'mass,position,velocity', got '" +
                                  std::string(line.substr(0, 80)) + "'");
      }
      header_seen = true;
      continue;
    }
    readBody(line, line_number, scene);
  }
  if (!header_seen) {
    throw BodiesFileError(BodiesFileError::Kind::kHeader, "bodies",
                          "the file is empty; the first line must be the header 'mass,position,velocity'");
  }
  return scene;
}

core::Scene readBodiesFile(const std::string& path) {
  if (path == "-") return readBodiesCsv(std::cin);
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    throw BodiesFileError(BodiesFileError::Kind::kUnreadable, "bodies", "cannot open '" + path + "'");
  }
  return readBodiesCsv(in);
}

}  // namespace io
}  // namespace collision_lab
