// The committed fuzz corpora (fuzz/corpus/core, fuzz/corpus/nbody) replayed through the
// fuzz targets' own entry points, built without libFuzzer: every input must pass the
// targets' invariants (a violation aborts the test with its one-line reason). The corpus
// runs clean in every build, not only where clang and libFuzzer are installed
// (scripts/fuzz.sh runs the fuzzers themselves).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

int collisionLabCoreFuzzOne(const std::uint8_t* data, std::size_t size);
int collisionLabNbodyFuzzOne(const std::uint8_t* data, std::size_t size);

namespace {

/// Every file of the corpus folder `name` under fuzz/corpus, in name order.
std::vector<std::filesystem::path> corpus(const std::string& name) {
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(std::string(COLLISION_LAB_SOURCE_DIR) + "/fuzz/corpus/" + name)) {
    if (entry.is_regular_file()) files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

/// The bytes of `file`, named on stderr first: a violated invariant aborts the test, after it.
std::vector<std::uint8_t> bytesOf(const std::filesystem::path& file) {
  std::fprintf(stderr, "replaying %s\n", file.string().c_str());
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(FuzzCorpus, TheCoreTargetRunsItsCorpusClean) {
  const auto files = corpus("core");
  ASSERT_GE(files.size(), 20u);
  for (const auto& file : files) {
    SCOPED_TRACE(file.filename().string());
    const std::vector<std::uint8_t> bytes = bytesOf(file);
    EXPECT_EQ(collisionLabCoreFuzzOne(bytes.data(), bytes.size()), 0);
  }
}

TEST(FuzzCorpus, TheNbodyTargetRunsItsCorpusCleanRingsWithEventsIncluded) {
  const auto files = corpus("nbody");
  ASSERT_GE(files.size(), 5u);
  bool ring_crash = false;
  for (const auto& file : files) {
    SCOPED_TRACE(file.filename().string());
    ring_crash = ring_crash || file.filename() == "ring_crash_issue32_events_all";
    const std::vector<std::uint8_t> bytes = bytesOf(file);
    EXPECT_EQ(collisionLabNbodyFuzzOne(bytes.data(), bytes.size()), 0);
  }
  EXPECT_TRUE(ring_crash);  // the crash, with events all, is in the corpus
}

}  // namespace
