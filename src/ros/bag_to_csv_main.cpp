// bag_to_csv RUN.bag [OUTDIR]: one CSV per topic of a collision_lab bag plus the tidy
// per-body tables bodies.csv and final_velocities.csv, with units in the column names (see
// bag_csv.h). OUTDIR defaults to RUN_csv in the current folder, so that the node's runs
// folder keeps its bags only.
#include <filesystem>
#include <iostream>
#include <string>

#include <ros/time.h>

#include "collision_lab/ros/bag_csv.h"

int main(int argc, char** argv) {
  if (argc < 2 || argc > 3 || std::string(argv[1]) == "-h" || std::string(argv[1]) == "--help") {
    std::cerr << "usage: bag_to_csv RUN.bag [OUTDIR]\n"
                 "Writes one CSV per topic of RUN.bag (collision_events.csv, run_summaries.csv, ...)\n"
                 "and, one row per body, bodies.csv (the start and the bodies after each event)\n"
                 "and final_velocities.csv into OUTDIR (default: RUN_csv in the current folder),\n"
                 "with units in the column names.\n";
    return 2;
  }
  const std::string bag = argv[1];
  const std::string out_dir = argc == 3 ? argv[2] : std::filesystem::path(bag).stem().string() + "_csv";
  ros::Time::init();
  try {
    const auto result = collision_lab_ros::bagToCsv(bag, out_dir);
    for (const auto& file : result.files) {
      std::cout << file.path << ": " << file.rows << " rows from " << file.topic << "\n";
    }
    for (const auto& topic : result.skipped_topics) std::cerr << "skipped " << topic << "\n";
    for (const auto& warning : result.warnings) std::cerr << "warning: " << warning << "\n";
    if (result.files.empty()) {
      std::cerr << "bag_to_csv: " << bag << " holds no collision_lab messages\n";
      return 1;
    }
  } catch (const collision_lab_ros::BagCsvError& e) {
    std::cerr << "bag_to_csv: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
