// Where the views sit and how they look: every position, size, line width, colour and
// scale of the rviz markers, in one place [rviz units unless stated].
// rviz/collision_lab.rviz looks down at (2.8, 0.85), 46 px per unit; its 1248 x 708 pixel
// view shows x in [-10.7, 16.3] and y in [-6.8, 8.5].
#pragma once

#include <cstddef>

#include "collision_lab/ros/view_style.h"

namespace collision_lab_ros::markers {

/// A rectangle in the marker frame [rviz units].
struct Box {
  double left, right, bottom, top;
  constexpr double midX() const { return (left + right) / 2; }
  constexpr double midY() const { return (bottom + top) / 2; }
};

namespace layout {

// ---- rows and panels ----
/// What rviz/collision_lab.rviz shows: texts are kept inside it.
constexpr Box kScreen{-10.7, 16.3, -6.8, 8.5};
constexpr double kCentreX = 2.8;
constexpr double kTitleY = 8.25, kNoteY = 7.8, kStatusY = 7.35, kVelocityRowY = 6.9;
constexpr double kSceneY = 6.05, kSceneLeft = -10.2, kSceneRight = 15.8, kZoomY = 5.05;
constexpr double kPanelTitleY = 4.55, kLegendY = 4.2;
constexpr Box kWedgeBox{-10.6, -4.6, -0.55, 3.65};
constexpr Box kBarsBox{-9.9, -5.3, -6.3, -2.6};
constexpr Box kVelocityBox{-2.2, 5.2, -0.35, 3.55};
constexpr Box kEnergyBox{-2.2, 5.2, -3.05, -1.55};
constexpr Box kMomentumBox{-2.2, 5.2, -6.1, -4.6};
constexpr Box kWorldBox{8.3, 15.9, -6.1, 3.55};
constexpr double kHintY = 1.5;

// ---- text heights, depths ----
constexpr double kTextSize = 0.32, kSmallTextSize = 0.29, kTitleSize = 0.38;
/// Large, and bold (drawn twice, kBoldDy apart): rviz draws an underscore a pixel thin and
/// faint, and the hint is a command to copy.
constexpr double kHintTextSize = 0.44;
constexpr double kBoldDy = 0.022;  ///< about one pixel at the config's 46 px per unit
constexpr double kTextZ = 0.2;  ///< texts over everything
constexpr double kDotZ = 0.05;  ///< dots over lines

// ---- colours: the view model's (view_style.h) ----

// ---- line widths ----
constexpr double kFrameWidth = 0.025, kAxisWidth = 0.03, kSeriesWidth = 0.035, kConservedWidth = 0.03;
constexpr double kCursorWidth = 0.02;

// ---- plots (frames, steps, index axis) ----
constexpr double kValueLabelDx = -0.55;  ///< a frame's top and bottom values, left of it
constexpr double kZeroLabelDx = -0.3;
/// A frame's label over it, and its top value a little under the top: a label as wide as
/// the frame keeps clear of that value.
constexpr double kFrameLabelDy = 0.3, kTopValueDy = -0.08;
constexpr double kLabelClearance = 0.3;  ///< an end value closer than this to zero gives way
constexpr double kRangePadding = 0.06;  ///< of the data's range, at each end
constexpr double kStartDotSize = 0.16;
constexpr double kShortestSeries = 0.1;  ///< shorter series get a start dot
constexpr double kMarkedWidth = 0.025, kMarkedZ = 0.02;
constexpr double kIndexLabelDy = -0.28;
constexpr unsigned kAllIndexLabelsUpTo = 12;  ///< beyond: the first and the last step only
constexpr double kPredictedDotSize = 0.09;
constexpr double kOwnPanelGap = 0.45;  ///< between B's panel and A's and C's
constexpr double kSeriesNameDx = 0.55, kSeriesNamePitch = 0.4;
/// The paper's series is drawn where it differs by more than this share of the panel.
constexpr double kPaperTolerance = 1e-6;
/// B gets its own panel when its largest speed exceeds A's and C's by this factor.
constexpr double kOwnScaleFactor = 5.0;
/// The paper's velocities widen a panel's scale at most this much; beyond, they are clipped.
constexpr double kPaperScaleFactor = 4.0;
/// At most this many closed-form dots per series (they sit on the simulated steps).
constexpr std::size_t kMaxPredictedDots = 200;

// ---- the scene and its magnifier ----
/// The axis' end labels, under it and under a cluster's ring around a body on it.
constexpr double kSceneLabelDx = 0.9, kSceneLabelDy = -0.82;
constexpr double kWallLabelDy = 0.25;  ///< an end label under a wall, from the wall's foot
constexpr double kSmallestBody = 0.35, kBodyGrowth = 0.55;  ///< diameter over the mass decades
constexpr double kWallWidth = 0.2, kWallHeight = 1.8, kWallDepth = 0.3;
constexpr double kWallTagDx = 0.8, kTagDy = 0.5;
/// Tags of bodies close together: at least this far apart, moved sideways by at most this
/// many tag widths.
constexpr double kTagGap = 0.08;
constexpr int kTagMaxSteps = 4;
constexpr double kVelocityRowPitch = 6.8;
/// The magnifier shows while three bodies are closer than this share of the scene's axis.
constexpr double kCrowded = 0.05;
constexpr double kZoomMargin = 1.6;   ///< the window is a power of ten >= this x their spread
/// Four to kMaxPlottedBodies bodies: the magnifier shows while two neighbours lie closer
/// than kZoomCrowdedGap on the scene's axis and it magnifies at least kZoomLeast times; its
/// window is 1, 2 or 5 times a power of ten, >= kZoomMargin x their spread.
constexpr double kZoomCrowdedGap = 1.0, kZoomLeast = 2.0;
constexpr double kZoomInset = 5.0;    ///< from each end of the scene's axis
constexpr double kZoomLightSize = 0.16, kZoomHeavySize = 0.26, kZoomWallWidth = 0.08, kZoomWallHeight = 0.6;
constexpr double kZoomLightZ = 0.3;  ///< B, the light one, on top: at a collision it touches A or C
constexpr double kZoomMagnificationDx = -2.2, kZoomWindowDx = 2.5;

// ---- the wedge in velocity space ----
constexpr double kWedgeRadius = 2.1;
constexpr double kWedgeX = kWedgeBox.midX(), kWedgeY = kWedgeBox.midY();
constexpr int kConeSegments = 32, kCircleSegments = 96;
constexpr double kConeZ = -0.01;
constexpr double kWedgeLineWidth = 0.03, kCircleWidth = 0.012, kPathWidth = 0.025;
constexpr double kLineLabelRadius = 1.14 * kWedgeRadius;
/// L_AB's label moves up by kNarrowConeDy when the cone is narrower than this [rad].
constexpr double kNarrowCone = 0.3, kNarrowConeDy = 0.35;
/// The path's circle: |u_perp| at this share of the wedge's radius.
constexpr double kPathRadius = 0.8 * kWedgeRadius;
constexpr double kSimulatedDotSize = 0.16, kPredictedWedgeDotSize = 0.08, kCursorSize = 0.3, kCursorZ = 0.1;
/// The legend: the orange key in the legend row, the rest (at most two lines) under the caption.
constexpr double kStartLabelDy = -0.3, kCaptionDy = -0.1, kWedgeLegendDy = -0.65;
/// Texts of the left column fit this width, so they stay on screen and clear of the middle.
constexpr double kLeftTextWidth = kWedgeBox.right - kWedgeBox.left;
/// At most this many states per series in the wedge when not every collision is kept.
constexpr std::size_t kMaxWedgeDots = 600;

// ---- many bodies: mass classes, the colour legend ----
/// Bodies of a large scene are drawn in this many mass classes (log scale), one list each.
constexpr int kMassClasses = 4;
constexpr double kManyBodySize = 0.18;     ///< the lightest class's diameter
constexpr double kManyBodyGrowth = 0.12;   ///< added per class
constexpr Box kColourBarBox{-3.0, 3.0, 5.0, 5.2};
constexpr int kColourBarSteps = 24;
constexpr double kColourLabelDx = 1.1;

// ---- in the wedge's place: velocities now (profile or histogram) ----
constexpr Box kSideBox{-10.0, -4.6, -0.3, 3.45};
/// The histogram leaves room over it for the mean and spread now (kHistogramTextY).
constexpr Box kHistogramBox{kSideBox.left, kSideBox.right, kSideBox.bottom, 2.95};
constexpr double kHistogramTextY = 3.3;
/// The note under the side view's axis labels (at most two lines), from its box's bottom.
constexpr double kSideNoteDy = -0.9;
constexpr int kHistogramBins = 24;
constexpr int kGaussianSegments = 64;
constexpr double kProfileDotSize = 0.16;

// ---- the x-t diagram ----
constexpr double kWallLineWidth = 0.08, kBodyLineWidth = 0.03;
constexpr double kWorldZeroDx = -0.3, kWorldEndDx = -0.55, kWorldUnitDx = -0.45, kWorldUnitDy = 0.3;
constexpr double kWorldPositionDy = -0.3;
constexpr double kWorldPeriodsDy = -0.35;  ///< the periods so far, under the legend
/// The x-t legend's lines keep this far inside the box's sides [rviz units]: its second
/// line passes right of the "t [s]" label.
constexpr double kWorldLegendInset = 0.2;
/// The index plots' periods so far: in the same row, right of the frame's label.
constexpr double kStepsPeriodsDx = -1.2;  ///< from the velocity box's right edge
/// A periodic motion is drawn over one period once the run lasts this many periods.
constexpr double kPeriodsToFold = 2.0;
/// Large scenes: "x range: the bodies now" left of the scene's right end label, this far.
constexpr double kSceneRangeNoteGap = 1.0;
/// Large scenes: a worldline drawn up to now keeps first, lowest, highest, last x per row.
constexpr int kWorldRows = 240;
constexpr double kWorldNowDotSize = 0.16;
/// The ghosts' dashes lie over the worldlines: a dash and a gap every kGhostDashPeriod,
/// the dash taking kGhostDashShare of it.
constexpr double kGhostWidth = 0.03, kGhostZ = 0.03, kGhostDashPeriod = 0.3, kGhostDashShare = 0.5;
constexpr Rgba kGhostGrey{0.8, 0.8, 0.8};

// ---- the kinetic energy bars ----
constexpr double kBarNameDy = -0.3, kBarsTitleDy = 0.75;
constexpr double kBarWidth = 0.6;  ///< share of the pitch
constexpr double kBarMinHeight = 0.01, kBarDepth = 0.1, kBarValueDy = 0.25, kBarValueStagger = 0.32;

// ---- large inelastic scenes: T(t) on log-log axes, in the energy bars' place ----
constexpr Box kTemperatureBox{-9.4, -5.4, -5.75, -3.45};
constexpr double kTemperatureLegendY = -2.75;  ///< under the title (three lines)
constexpr double kTemperatureNowY = -6.45;    ///< T and E now, under the time axis' labels
constexpr double kTickLength = 0.1;
constexpr int kHaffSegments = 64;
constexpr Rgba kHaffCyan{0.3, 0.85, 1.0};
constexpr double kTemperatureWidth = 0.05;  ///< T(t), over the thinner fit

// ---- clusters: bodies moving together ----
constexpr Rgba kClusterAmber{1.0, 0.75, 0.2, 0.9};
constexpr double kClusterRingWidth = 0.05, kClusterRingMargin = 0.12;  ///< beyond the largest body's radius
constexpr int kClusterRingSegments = 24;
constexpr double kClusterNamesX = 11.0;  ///< centre of the clusters' names, in the note row
constexpr std::size_t kMaxClusterNames = 3;
constexpr double kClusterLineWidth = 0.09;  ///< a cluster's worldline, under the bodies'
constexpr std::size_t kMaxClusterSegments = 4000;

// ---- framed texts (banner, hint) ----
/// rviz's font is about 0.42 text heights wide per character, 1.25 high per line.
constexpr double kHalfCharWidth = 0.21, kHalfLineHeight = 0.62;
constexpr double kFrameMarginX = 0.4, kFrameMarginY = 0.2, kMaxHalfFrameWidth = 13.0;
constexpr double kFramedBoxWidth = 0.03;
/// A framed text's panel is this much wider than the usual estimate of its text: capitals
/// (REJECTED, reason names) are wider than the average character.
constexpr double kFramedWidthFactor = 1.2;
/// The panels lie over every view (bodies reach z = 0.45), their texts over the panels.
constexpr double kOverlayZ = 1.0, kOverlayTextDz = 0.1;
constexpr Rgba kOverlayBackground{0.12, 0.125, 0.157};  ///< rviz's background (30, 32, 40)
/// The rejection banner's bottom edge: over the panels' titles, growing up over the scene.
constexpr double kBannerBottomY = kPanelTitleY + 0.3;

}  // namespace layout
}  // namespace collision_lab_ros::markers
