// From a bag to CSV files, one per topic, for spreadsheets and Python
// (`bag_to_csv RUN.bag [OUTDIR]`). Every collision_lab message type has its own table of
// columns; each header names the column and its unit, e.g. `time_s`, `v_a_m_s`,
// `delta_a_J`, `alpha_rad`. Arrays of A, B, C become three columns (_a, _b, _c).
// Numbers round-trip: doubles are written with 17 significant digits ("inf", "-inf",
// "nan" as Python's float() reads them), header.stamp as exact seconds with 9 decimals.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>
#include <vector>

namespace collision_lab_ros {

/// The bag cannot be read, or the output folder cannot be written. what() says which.
struct BagCsvError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct CsvFile {
  std::string topic;
  std::string path;
  std::size_t rows = 0;
};

struct CsvExport {
  std::vector<CsvFile> files;               ///< in the order topics first appear
  std::vector<std::string> skipped_topics;  ///< "topic (type)": not a collision_lab message
};

/// Writes <out_dir>/<last part of topic>.csv for every topic of the bag that holds a
/// collision_lab message type, rows in bag order (the full topic, with '/' as '_', when
/// two topics share a last part). Creates out_dir. Throws BagCsvError.
CsvExport bagToCsv(const std::string& bag_path, const std::string& out_dir);

/// The CSV columns of a collision_lab message type and, for each, the message field it
/// comes from ("header" for stamp_s); for tests that check every field is exported.
struct CsvColumn {
  std::string name;
  std::string field;
};
/// Empty for a type that is not exported, e.g. "collision_lab/CollisionEvent".
std::vector<CsvColumn> csvColumns(const std::string& datatype);

}  // namespace collision_lab_ros
