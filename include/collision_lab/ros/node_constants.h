// Default topic names (relative: the launch files put them in namespace collision_lab;
// remap as needed), queue sizes and parameter defaults of the collision_lab nodes.
#pragma once

#include <cstddef>
#include <cstdint>

#include "collision_lab/service/envelope.h"

namespace collision_lab_ros {

constexpr char kInitialConditionsTopic[] = "initial_conditions";
constexpr char kPredictionsTopic[] = "predictions";
constexpr char kCollisionEventsTopic[] = "collision_events";
constexpr char kVelocitiesTopic[] = "velocities";
constexpr char kEnergyTransfersTopic[] = "energy_transfers";
constexpr char kRunSummariesTopic[] = "run_summaries";
/// Live only, not latched, never recorded: a run's RunProgress past ~max_published_events.
constexpr char kRunProgressTopic[] = "run_progress";
constexpr char kRejectedTopic[] = "rejected";
/// One AcceptedRun per accepted input: the run_id it got.
constexpr char kAcceptedRunsTopic[] = "accepted_runs";
/// Each run's InitialConditions as served (its run_id filled in, stamped at the run's
/// start), first of the run's messages: what a live collision_lab_markers (~live) draws
/// from; initial_conditions carries the inputs as sent.
constexpr char kServedInputsTopic[] = "served_inputs";
/// The run's picture that changes only when a message arrives (axes, plots, titles), and
/// the animation's frames (bodies, counter, cursors, banners). Both are latched, so an
/// rviz opened late shows the last run and its last frame at once.
constexpr char kMarkersTopic[] = "markers";
constexpr char kAnimatedMarkersTopic[] = "markers_animated";

/// Latched: a late joiner (rviz or `rostopic echo` started after a run, a second client)
/// gets the newest of these at once. predictions and run_summaries: the newest run's
/// prediction and result, what a late window needs to show it. rejected: the answer to
/// "why did nothing happen?" for whoever looks after the fact; its stamp, run_id and
/// student say whose it was. Not latched: the per-collision topics (their last message
/// alone is a fragment of a run), initial_conditions and served_inputs (a late-joining
/// node or view would serve or draw a stale scene again) and /diagnostics (periodic).
constexpr bool kLatchPredictions = true;
constexpr bool kLatchRunSummaries = true;
constexpr bool kLatchRejected = true;
/// accepted_runs: the newest accepted input's run_id, for a `rostopic echo -n1` just after
/// a `rostopic pub` (in a busy class, ~list_runs has every run).
constexpr bool kLatchAcceptedRuns = true;
/// The runs running and waiting (RunQueue), latched: a late page shows the queue at once.
constexpr char kRunQueueTopic[] = "run_queue";
constexpr bool kLatchRunQueue = true;
/// run_queue lists every running run and at most this many waiting ones (the first to be
/// served): a burst of thousands of inputs is not republished whole at every change.
constexpr std::size_t kRunQueueListed = 500;
/// run_queue's messages come at most this often [s]; the latched one is the newest state
/// once the period has passed.
constexpr double kRunQueuePeriod = 0.05;
/// Bag only (the node does not publish it): the settings of the run (RunParameters),
/// written first in each bag, latched on replay like the run's other one-shot messages.
constexpr char kRunParametersTopic[] = "run_parameters";
constexpr bool kLatchRunParameters = true;

/// Private services of collision_lab_node (srv/RunScene.srv, srv/RunPreset.srv).
constexpr char kRunSceneService[] = "run_scene";
constexpr char kRunPresetService[] = "run_preset";
/// Stops a running or waiting run (srv/Cancel.srv); served by a thread of its own.
constexpr char kCancelService[] = "cancel";
/// Lists the runs served (srv/ListRuns.srv); served by ~cancel's thread (quick answers).
constexpr char kListRunsService[] = "list_runs";
/// ~list_runs lists from the run index; only when the index cannot be opened does it list
/// the runs the node keeps in memory, the newest this many (about 300 bytes each): a
/// class's last runs, and the node's memory flat after its first few hundred runs.
constexpr std::size_t kServedRunsKept = 200;
/// InitialConditions.student: at most this many characters.
constexpr std::size_t kMaxStudentLength = collision_lab::service::kMaxStudentLength;
/// Service calls served at once; each blocks its thread until its run is over (the runs
/// themselves are served by the workers). Further calls wait in roscpp.
constexpr std::uint32_t kServiceThreads = 4;
/// ~scenario_file default, relative to the package folder.
constexpr char kDefaultScenarioFile[] = "config/scenarios.yaml";
/// Where diagnostic_updater publishes (absolute by the ROS convention: the diagnostic
/// aggregator listens there).
constexpr char kDiagnosticsTopic[] = "/diagnostics";
constexpr double kDiagnosticsPeriod = 1.0;  ///< [s]
/// The free-space floor of bag_directory [MB]: below it inputs are refused (DISK_SPACE)
/// and a recording run is stopped (SERVICE_DISK_SPACE); /diagnostics warns below
/// kFreeSpaceWarnFactor times it.
constexpr double kDefaultMinFreeSpaceMb = 100.0;
constexpr double kFreeSpaceWarnFactor = 5.0;
/// [bytes] a recording run writes between two looks at the free space.
constexpr std::uint64_t kFreeSpaceProbeBytes = 1u << 20;

/// Inputs arrive in bursts from scripts; the subscriber callback only queues them (the
/// worker's queue is unbounded), so this covers bursts of up to 10,000 inputs between two
/// spins.
constexpr std::uint32_t kInputQueueSize = 10000;
/// Per-run topics: a burst of runs may queue many messages per subscriber link before a
/// slow subscriber reads them. roscpp drops the oldest beyond this, so it is sized for
/// ~max_published_events per run times a burst of runs.
constexpr std::uint32_t kOutputQueueSize = 100000;
/// Markers are snapshots: only the newest matters.
constexpr std::uint32_t kMarkerQueueSize = 10;

constexpr std::uint64_t kDefaultMaxCollisions = 10'000'000;
/// Scheduling (docs/ros.md, "Scheduling and limits"): ~workers defaults to the hardware
/// threads, at least kMinDefaultWorkers; ~short_lane_workers of them take only short runs.
constexpr std::uint64_t kMinDefaultWorkers = 2;
constexpr std::uint64_t kDefaultShortLaneWorkers = 1;
constexpr std::uint64_t kMaxWorkers = 256;
/// A run is short when its plan says it computes at most this many impacts [1], or, when
/// the plan knows no count, when its cap's impacts take at most kDefaultShortMaxSeconds [s]
/// at the rate of its first impacts (service::chooseLane).
constexpr std::uint64_t kDefaultShortMaxCollisions = 100'000;
constexpr double kDefaultShortMaxSeconds = 1.0;
/// Service ceilings an input may lower: wall time per run [s] and recorded bytes per bag
/// [bytes] (the serialized size of the messages recorded).
constexpr double kDefaultMaxRunSeconds = 300.0;
constexpr std::uint64_t kDefaultMaxBagBytes = 2'000'000'000;
/// How often the watchdog checks the runs' deadlines [s].
constexpr double kWatchdogPeriod = 0.02;
/// run_ids a node remembers to refuse again (the newest this many): bounded memory. With
/// recording on, the bag folder remembers them all (claimBag).
constexpr std::size_t kRunIdsRemembered = 4096;
/// ~max_bodies: a larger scene is rejected (TOO_MANY_BODIES), so that a typo in a script
/// cannot flood a lab machine; a 10,000-body gas still runs.
constexpr std::uint64_t kDefaultMaxBodies = 10'000;
/// Per run; beyond it, events go to the bag only. Keeps a 2-million-collision run from
/// putting 6 million messages on the network.
constexpr std::uint64_t kDefaultMaxPublishedEvents = 10'000;
/// Past it, a run's progress (RunProgress) goes out at most this often [s] of wall time:
/// a live counter at 10 Hz, a few hundred bytes each for small scenes.
constexpr double kDefaultProgressPeriod = 0.1;
/// Recording: a run's events go to the bag writer thread in batches of this many (a
/// long run never sits whole in memory), and the worker blocks while this many recorded
/// messages wait to be written (about 40 MB for three bodies): backpressure, never loss.
constexpr std::size_t kRecordBatchEvents = 1024;
constexpr std::size_t kRecordQueueMessages = 100'000;
/// /diagnostics reports the median and p99 of the worker's recording hand-over time
/// over this many newest runs.
constexpr std::size_t kRecordingTimeWindow = 10'000;
/// Relative to $ROS_HOME (default ~/.ros), followed by the node's namespace
/// (/collision_lab: collision_lab/runs/collision_lab): one folder per lab by default.
constexpr char kDefaultBagSubdirectory[] = "collision_lab/runs";

constexpr double kDefaultMarkerRate = 20.0;  ///< [Hz]
/// Simulated seconds per wall second; 0 = auto: one loop of the run's animation takes
/// kAutoLoopDuration for a few collisions, up to about twice that for millions, with
/// dense bursts in slow motion (see TimeWarp).
constexpr double kDefaultTimeScale = 0.0;
constexpr double kAutoLoopDuration = 8.0;  ///< [s] wall time
/// Each loop ends by holding its last frame (the final count) this long [s] wall time.
constexpr double kMarkerEndHold = 2.5;
/// What the marker view keeps of one run, whatever its count (RunRecord): exact states
/// after this many selected collisions, and plotted series of at most this many vertices
/// each (beyond it, min/max per column: 256 to 512 columns, about a plot's pixels).
constexpr std::size_t kMarkerKeyframes = 4096;
constexpr std::size_t kMarkerEnvelopeVertices = 2048;
/// rviz draws LINE_STRIP and LINE_LIST markers with a BillboardLine whose chains hold at
/// most 65536 / 4 = 16384 elements (rviz 1.14 src/rviz/ogre_helpers/billboard_line.cpp,
/// MAX_ELEMENTS). A LINE_STRIP with more points is split over several lines, and the next
/// message for the same marker then fails ROS_ASSERT(num_lines_ == 1) (billboard_line.cpp
/// line 178) and aborts rviz. No line marker we publish has more points than this; the
/// builders stay far below it (Envelope), and enforceRvizLimits() guards the output.
constexpr std::size_t kRvizMaxLinePoints = 16384;
constexpr char kMarkerFrame[] = "collision_lab";

}  // namespace collision_lab_ros
