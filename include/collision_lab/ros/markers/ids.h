// Every rviz marker of the views by namespace (Marker.ns) and id (Marker.id): one enum,
// grouped by namespace. rviz replaces a marker of the same ns and id, so each name below is
// one thing on screen. Where a name is a base, the marker's id is base + an offset (a
// body's index i: 0 A, 1 B, 2 C; a frame part; a label's position), as its comment says.
#pragma once

namespace collision_lab_ros::markers {

/// The namespaces. rviz/collision_lab.rviz shows them all (two MarkerArray displays).
namespace ns {
// static: rebuilt when a message arrives (topic `markers`)
constexpr const char* kTitle = "title";
constexpr const char* kScene = "scene";
constexpr const char* kWedge = "wedge";
constexpr const char* kPlot = "plot";            // velocity steps and the paper's series
constexpr const char* kConserved = "conserved";  // energy and momentum steps
constexpr const char* kWorldlines = "worldlines";
constexpr const char* kEnergy = "energy";        // the kinetic energy bars' axis
constexpr const char* kVelocities = "velocities";  // in the wedge's place: profile or histogram
constexpr const char* kTemperature = "temperature";  // large inelastic scenes: T(t), log-log, and Haff's law
// animated: every frame (topic `markers_animated`)
constexpr const char* kBodies = "bodies";
constexpr const char* kLabels = "labels";
constexpr const char* kZoom = "zoom";  // the magnifier
constexpr const char* kWedgeNow = "wedge_now";
constexpr const char* kPlotCursor = "plot_cursor";
constexpr const char* kWorldlinesNow = "worldlines_now";
constexpr const char* kEnergyBars = "energy_bars";
constexpr const char* kVelocitiesNow = "velocities_now";
constexpr const char* kTemperatureNow = "temperature_now";
constexpr const char* kClusters = "clusters";  // bodies moving together, in the scene and the x-t diagram
// overlays, also on `markers_animated`
constexpr const char* kRejected = "rejected";
constexpr const char* kHint = "hint";
}  // namespace ns

enum MarkerId : int {
  // ns "title"
  kTitleText = 0,

  // ns "scene"
  kSceneAxis = 0,
  kSceneMinLabel = 1,
  kSceneMaxLabel = 2,
  kSceneNote = 4,  ///< what the picture does not show
  kColourBar = 5,  ///< large scenes: the colour by velocity's legend
  kColourMin = 6,
  kColourMax = 7,
  kColourCaption = 8,  ///< what the colours mean: RunView::colour_legend
  kColourSize = 9,     ///< "size: mass (log)", right of the bar

  // a plot frame (addFrame): base + these
  kFrameLines = 0,
  kFrameTopValue = 1,
  kFrameBottomValue = 2,
  kFrameZeroLabel = 3,
  kFrameLabel = 4,
  kFrameLabelBold = 5,  ///< the label again, a pixel lower (bold)
  /// A series' start dot (when its known part is too short to see): the series' id + this.
  kSeriesStartDot = 1000,

  // ns "wedge"
  kWedgeCone = 0,
  kWedgeLines = 1,  ///< L_BC and L_AB
  kWedgeBcLabel = 2,
  kWedgeAbLabel = 3,
  kWedgeCaption = 4,  ///< the cone's colour and alpha
  kWedgeCircle = 5,   ///< |u_perp| is conserved: the path lies on it
  kWedgePath = 6,
  kWedgeSimulated = 7,
  kWedgePredicted = 8,
  kWedgeStartLabel = 9,
  kWedgeTitle = 10,
  kWedgeLegend = 11,
  kWedgeDirections = 12,  ///< e < 1: the directions of u_perp, on the circle
  kWedgeEigen = 13,       ///< collapse: the cycle's eigen-directions
  kWedgeKey = 14,         ///< the orange key, in the legend row

  // ns "plot": panel p (0, or 1 for A and C when B has its own) at p * kPlotPanelStride
  kPlotPanelStride = 100,
  kPlotFrame = 0,       ///< + kFrame*
  kPlotSeries = 10,     ///< + body index
  kPlotPredicted = 20,  ///< + body index: the closed form's dots
  kPlotPaper = 30,      ///< + body index: the paper's series where it differs
  kPlotTitle = 310,
  kPlotLegend = 311,
  kPlotSeriesNames = 320,  ///< + body index
  kPlotIndexLabels = 400,  ///< + label number
  kPlotTracked = 500,      ///< large scenes: + tracked body's slot (RunRecord::trackedBodies)

  // ns "conserved"
  kConservedEnergy = 0,     ///< base of the energy plot
  kConservedMomentum = 100, ///< base of the momentum plot
  kConservedSeries = 10,    ///< base + this
  kConservedIndexLabels = 20,  ///< base + this + label number
  kConservedLost = 50,         ///< energy plot: the heat so far
  kConservedBodies = 60,       ///< energy plot: + plotted body index

  // ns "worldlines"
  kWorldFrame = 0,
  kWorldTimeZero = 1,
  kWorldTimeEnd = 2,
  kWorldTimeUnit = 3,
  kWorldPositionMin = 4,
  kWorldPositionMax = 5,
  kWorldPositionUnit = 6,
  kWorldTitle = 7,
  kWorldLegend = 8,
  kWorldLines = 10,  ///< + tracked body's slot (RunRecord::trackedBodies)
  kWorldGhosts = 50, ///< equal elastic masses: the ghosts' straight worldlines

  // ns "energy"
  kEnergyAxis = 0,
  kEnergyTitle = 4,
  kEnergyBodyNames = 10,  ///< + body index

  // ns "velocities" (in the wedge's place)
  kSideFrame = 0,  ///< + kFrame*
  kSideTitle = 10,
  kSideLegend = 11,
  kSideAxisLabel = 12,
  kSideAxisMin = 13,
  kSideAxisMax = 14,
  kSideNote = 15,  ///< under the axis labels (the histogram's Gaussian)

  // ns "bodies"
  kBody = 0,         ///< + body index (small scenes)
  kBodyClass = 10,   ///< large scenes: + mass class (a SPHERE_LIST each)
  kBodyWall = 20,    ///< large scenes: + 0 (body 0) or 1 (body N-1)

  // ns "labels"
  kStatus = 3,
  kSceneNowMin = 4,    ///< large scenes: the scene's ends, the bodies' spread now
  kSceneNowMax = 5,
  kSceneRangeNote = 6,
  kBodyTag = 100,      ///< + body index
  kVelocityRow = 200,  ///< + body index

  // ns "zoom"
  kZoomLine = 0,
  kZoomMagnification = 1,
  kZoomWindow = 2,
  kZoomBody = 3,     ///< + body index (up to kMaxPlottedBodies bodies)
  kZoomCount = 13,  ///< ids 0 .. kZoomCount - 1

  // ns "wedge_now", "plot_cursor"
  kCursor = 0,
  kStepsPeriods = 1,  ///< "plot_cursor": a periodic motion's periods so far

  // ns "worldlines_now"
  kWorldNowLine = 0,
  kWorldNowBodies = 1,
  kWorldNowTimeEnd = 2,   ///< large scenes: the axes' ends, up to now
  kWorldNowPeriods = 3,   ///< a periodic motion: the periods so far
  kWorldNowPositionMin = 4,
  kWorldNowPositionMax = 5,
  kWorldNowLines = 10,    ///< large scenes: + tracked body's slot
  kWorldNowGhosts = 50,

  // ns "energy_bars"
  kEnergyBar = 0,       ///< + body index
  kEnergyBarValue = 10, ///< + body index
  kEnergyTotals = 100,  ///< large scenes: the totals now

  // ns "velocities_now"
  kSideBars = 0,      ///< the histogram's bars or the profile's dots
  kSideGaussian = 1,  ///< the Maxwell-like Gaussian
  kSideNowText = 2,   ///< its mean and spread

  // ns "temperature"
  kTemperatureFrame = 0,
  kTemperatureTitle = 1,
  kTemperatureLegend = 2,
  kTemperatureTimeMin = 3,
  kTemperatureTimeMax = 4,
  kTemperatureMin = 5,
  kTemperatureMax = 6,
  kTemperatureTicks = 7,  ///< a tick at every decade of t and of T
  kTemperatureSeries = 8,
  kTemperatureHaff = 9,
  kTemperatureUnits = 10,

  // ns "temperature_now"
  kTemperatureNowDot = 0,
  kTemperatureNowText = 1,

  // ns "clusters" (animated)
  kClusterRings = 0,   ///< a ring around each cluster in the scene
  kClusterLines = 1,   ///< the clusters' joined worldlines in the x-t diagram
  kClusterLabel = 2,   ///< the clusters' names

  // ns "rejected" and "hint": a framed text
  kFramedText = 0,
  kFramedBox = 1,
  kFramedTextBold = 2,  ///< the hint: its text again, a pixel lower (bold)
};

}  // namespace collision_lab_ros::markers
