// The run index (service/run_index.h) as the web node's RunSource.
#include <memory>

#include "collision_lab/service/run_index.h"
#include "collision_lab/web/run_source.h"

namespace collision_lab_web {

namespace {

class IndexRunSource : public RunSource {
 public:
  explicit IndexRunSource(const std::string& path) : index_(path) {}
  std::optional<collision_lab::service::IndexedRun> find(const std::string& run_id) const override {
    return index_.find(run_id);
  }
  std::vector<collision_lab::service::IndexedRun> list(const std::optional<std::string>& student) const override {
    return index_.list(student);
  }
  std::vector<collision_lab::service::IndexedRejection> rejections(const std::optional<std::string>& student,
                                                                  std::size_t limit) const override {
    return index_.rejections(student, limit);
  }

 private:
  collision_lab::service::RunIndex index_;
};

}  // namespace

std::shared_ptr<const RunSource> openIndexRunSource(const std::string& path) {
  return std::make_shared<IndexRunSource>(path);
}

}  // namespace collision_lab_web
