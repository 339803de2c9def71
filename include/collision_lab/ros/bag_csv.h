// From a bag to CSV files, for spreadsheets and Python (`bag_to_csv RUN.bag [OUTDIR]`), for
// scenes of any size N. Each header names the column and its unit (`time_s`, `x_m`,
// `v_m_s`, `energy_lost_J`, `alpha_rad`); docs/ros.md lists the files.
//  - <topic>.csv, one row per message of a collision_lab topic: stamp_s (the bag's ROS
//    time, seconds since the epoch), the simulated time time_s (the message's `time`; 0 for
//    InitialConditions and Prediction, stamped at the run's start) and the scalar fields (a
//    fixed pair array [2] as two columns _0 and _1). initial_conditions.csv also has the
//    masses, positions and velocities as lists. Other per-body arrays are not columns here:
//  - bodies.csv, tidy, one row per body and event: the start (index 0, from
//    InitialConditions) and the bodies after each CollisionEvent. Up to
//    CollisionEvent::FULL_STATE_MAX_BODIES bodies the event carries every body and every
//    body has a row (column moved: whether the event moved it; the last column, kind, says
//    start, impact or collapse: a collapse keeps its last impact's index); above, the event carries
//    the pair fields only, and the rows are those of the bodies it moved (first_moved ..
//    last_moved), rebuilt by the core's replay of the run (core::BodyStateReplay): velocity
//    from pair_velocities_after, position = the contact point, velocity before, kinetic
//    energy and its change from the run's state so far. A 1,000-body gas has 245,308 impacts: every body after every
//    impact would be 245 million rows.
//  - final_velocities.csv, tidy: Prediction's and RunSummary's final velocities, one row
//    per body.
//  - A list in a topic's CSV (InitialConditions' arrays, the plot topics' v, delta,
//    kinetic) is one cell, values separated by ';' (empty: an empty list).
// Numbers round-trip: doubles are written with the shortest digits that read back to the
// same double (io::writeCsvNumber: 0.9, not 0.90000000000000002; "inf", "-inf", "nan" as
// Python's float() reads them), header.stamp as exact seconds with 9 decimals.
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
  std::string topic;  ///< the topic; for bodies.csv and final_velocities.csv, their topics joined by " + "
  std::string path;
  std::size_t rows = 0;
};

struct CsvExport {
  std::vector<CsvFile> files;               ///< topics in the order they first appear, then the tidy tables
  std::vector<std::string> skipped_topics;  ///< "topic (type)": not a collision_lab message
  /// Events above FULL_STATE_MAX_BODIES whose run has no InitialConditions in the bag: no
  /// body rows (nothing to rebuild from); one line per run.
  std::vector<std::string> warnings;
};

/// Writes <out_dir>/<last part of topic>.csv for every topic of the bag that holds a
/// collision_lab message type, rows in bag order (the full topic, with '/' as '_', when
/// two topics share a last part), and the tidy tables bodies.csv and final_velocities.csv
/// when the bag has their topics. Creates out_dir. Throws BagCsvError.
CsvExport bagToCsv(const std::string& bag_path, const std::string& out_dir);

/// A run's class table (bagToClassTable).
struct ClassTable {
  std::size_t bodies = 0;  ///< columns x_ and v_ per body
  std::size_t rows = 0;    ///< the start and one per event
  /// The run's RunSummary counts impacts the bag has no event for (recorded without events,
  /// or cut): the table is not the whole run; nothing is written when the bag holds fewer
  /// events than that count.
  bool events_missing = false;
  /// More than max_bodies bodies: nothing written (rows 0).
  bool too_many_bodies = false;
};

/// The class table of the run recorded in the bag (one run per bag, as collision_lab_node
/// writes them), written to csv_path: one row for the state at t = 0, then one after each
/// event, in full precision (io::writeCsvNumber). Columns: t_s (simulated time from 0),
/// collision (the impacts so far), event (start, impact, collapse), pair (the pair's name;
/// a collapse names its first and last body, "A..E"), x_<name>_m for every body (at that
/// time), v_<name>_m_s (just after), then the finite masses' p_total_kg_m_s and
/// kinetic_total_J (core::totalsOf: each the exact sum rounded once). Body names are
/// core::bodyName's (A is the rightmost). Positions are the event's when it carries every
/// body, else the core's replay of the run. A run of more than max_bodies bodies (a column
/// per body) writes nothing. Throws BagCsvError when the bag cannot be read, has no
/// InitialConditions, or csv_path cannot be written.
ClassTable bagToClassTable(const std::string& bag_path, const std::string& csv_path, std::size_t max_bodies);

/// The CSV columns of a collision_lab message type, each with the message field it comes
/// from ("header" for stamp_s) and its file ("" for the topic's own, else "bodies.csv" or
/// "final_velocities.csv"); for tests that check every field is exported.
struct CsvColumn {
  std::string name;
  std::string field;
  std::string file;
};
/// Empty for a type that is not exported, e.g. "std_msgs/String".
std::vector<CsvColumn> csvColumns(const std::string& datatype);

}  // namespace collision_lab_ros
