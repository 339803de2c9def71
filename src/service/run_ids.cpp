#include "collision_lab/service/run_ids.h"

namespace collision_lab::service {

std::optional<std::pair<std::string, std::uint64_t>> numberedRunId(const std::string& run_id) {
  const std::size_t digits = run_id.find_last_not_of("0123456789") + 1;
  if (digits == run_id.size() || run_id.size() - digits > 18) return std::nullopt;
  if (digits < 3 || run_id.compare(digits - 3, 3, "run") != 0) return std::nullopt;
  if (digits > 3 && run_id[digits - 4] != '.') return std::nullopt;
  return std::make_pair(run_id.substr(0, digits), std::stoull(run_id.substr(digits)));
}

void RememberedRunIds::add(const std::string& run_id) {
  if (!ids_.insert(run_id).second) return;
  order_.push_back(run_id);
  if (order_.size() > capacity_) {
    ids_.erase(order_.front());
    order_.pop_front();
  }
}

RunIdClaims::RunIdClaims(std::string prefix, std::size_t remembered, Ledger ledger)
    : prefix_(std::move(prefix)), given_(remembered), ledger_(std::move(ledger)) {}

bool RunIdClaims::claim(const std::string& run_id, std::string& error) {
  if (given_.contains(run_id)) return false;
  if (!ledger_.take_bag(run_id, error)) return false;
  given_.add(run_id);
  return true;
}

std::string RunIdClaims::fresh(std::string& error) {
  std::string run_id;
  do {
    run_id = prefix_ + std::to_string(++counter_);
  } while (!claim(run_id, error));
  return run_id;
}

std::string RunIdClaims::claimAsked(const std::string& requested, std::string& error) {
  if (const auto series = numberedRunId(requested)) {  // a student's n-th run: the next free number
    std::uint64_t n = series->second;
    const auto numbered = [&] { return series->first + std::to_string(n); };
    while (ledger_.served_before(numbered()) || !claim(numbered(), error)) ++n;
    return numbered();
  }
  std::string run_id = requested;
  for (std::uint64_t n = 2; ledger_.held(run_id) || !claim(run_id, error); ++n) {
    run_id = requested + "." + std::to_string(n);
  }
  return run_id;
}

}  // namespace collision_lab::service
