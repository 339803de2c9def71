// Runs of the core's engine fed to a RunRecord as the lab node sends them (no master), for
// the marker tests: every impact with the bodies it moved (pair fields only, as for large
// N), every collapse with the cluster's velocity, and the summary.
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

#include "collision_lab/core/nbody/engine.h"
#include "collision_lab/ros/marker_builder.h"

namespace marker_engine {

using collision_lab::CollisionEvent;
using collision_lab::core::Scene;
using collision_lab_ros::RunRecord;

struct GranularRun {
  collision_lab::core::SceneSimulation result;
  RunRecord record;
};

/// The engine's run fed to a RunRecord as the node sends it: every impact with the bodies
/// it moved (a cluster moves as one), every collapse with the cluster's velocity.
inline GranularRun runScene(const Scene& scene, std::uint64_t cap, const std::string& run_id = "granular") {
  collision_lab::InitialConditions input;
  input.run_id = run_id;
  input.masses = scene.masses, input.positions = scene.positions, input.velocities = scene.velocities;
  input.restitution = scene.restitution;
  input.ring = scene.ring;
  input.max_collisions = cap;
  GranularRun out{{}, RunRecord(input)};
  collision_lab::core::EngineOptions options;
  options.max_impacts = cap;
  out.result = collision_lab::core::runEngine(
      scene, options,
      [&](const collision_lab::core::ImpactRecord& r) {
        CollisionEvent msg;
        msg.run_id = run_id;
        msg.kind = CollisionEvent::KIND_IMPACT;
        msg.index = r.index;
        msg.pair_index = static_cast<std::uint32_t>(r.pair_index);
        msg.time = r.time, msg.position = r.position;
        msg.restitution = scene.restitutionOf(r.pair_index);
        msg.first_moved = static_cast<std::uint32_t>(r.first_moved);
        msg.last_moved = static_cast<std::uint32_t>(r.last_moved);
        msg.pair_velocities_before = {r.velocities_before[0], r.velocities_before[1]};
        msg.pair_velocities_after = {r.velocities_after[0], r.velocities_after[1]};
        msg.pair_energy_transfer = {r.energy_gained[0], r.energy_gained[1]};
        msg.energy_lost = r.energy_lost;
        msg.total_energy = msg.total_momentum = std::nan("");
        out.record.add(msg);
      },
      {},
      [&](const collision_lab::core::Collapse& c) {
        CollisionEvent msg;
        msg.run_id = run_id;
        msg.kind = CollisionEvent::KIND_COLLAPSE;
        msg.index = c.impacts_before;
        msg.time = c.time, msg.position = c.position;
        msg.pair_index = msg.first_moved = static_cast<std::uint32_t>(c.first_body);
        msg.last_moved = static_cast<std::uint32_t>(c.last_body);
        msg.pair_velocities_after = {c.velocity, c.velocity};
        msg.total_energy = msg.total_momentum = std::nan("");
        out.record.add(msg);
      });
  collision_lab::RunSummary summary;
  summary.simulated = true;
  summary.truncated = out.result.truncated;
  summary.collision_count = out.result.impact_count;
  if (summary.truncated) summary.truncation_reason = out.result.stop_message;  // as msg_conversion sends it
  out.record.summary = summary;
  return out;
}

/// 40 bodies of 1 kg and 2 kg alternately, 1 m apart, between two walls at rest, with
/// seeded velocities in [-1, 1] m/s, e = 0.9.
inline Scene boxGas() {
  Scene s;
  s.masses.push_back(std::numeric_limits<double>::infinity()), s.positions.push_back(41.0), s.velocities.push_back(0.0);
  std::uint64_t seed = 21;
  for (int i = 0; i < 40; ++i) {
    seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
    s.masses.push_back(i % 2 ? 2.0 : 1.0);
    s.positions.push_back(40.0 - i);
    s.velocities.push_back(static_cast<double>(seed >> 11) / 9007199254740992.0 * 2 - 1);
  }
  s.masses.push_back(std::numeric_limits<double>::infinity()), s.positions.push_back(-1.0), s.velocities.push_back(0.0);
  s.restitution = {0.9};
  return s;
}

}  // namespace marker_engine
