// The proxy tracker: per frame, segmentation (track/segmentation.h), motion prediction, robust
// point-to-plane ICP against the proxy's model (track/point_to_plane_icp.h), verification, and a
// global detection without any prior pose at the start and whenever tracking is lost. Each frame
// gets a status: tracked (a verified measurement), predicted (too little of the proxy visible,
// e.g. under the hand: the pose is extrapolated for a few frames) or lost (no pose).
//
// Verification (loss detection) rejects a pose when the inliers are too few or their residual too
// large, when the model would hide surfaces the camera sees behind it (free-space violation: the
// camera sees through where the model would be), or when the proxy is outside the play area.
#pragma once

#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>

#include "core/rgbd_frame.h"
#include "core/rigid3.h"
#include "core/triangle_mesh.h"
#include "track/appearance.h"
#include "track/motion_model.h"
#include "track/point_to_plane_icp.h"
#include "track/pose_filter.h"
#include "track/projective_refinement.h"
#include "track/proxy_model.h"
#include "track/segmentation.h"
#include "track/setup.h"
#include "track/table_plane.h"
#include "track/track_status.h"

namespace mmh::track {

struct DetectionOptions {
  // Orientation hypotheses: yaw_steps yaws about the table normal for each of the model's six
  // axis directions pointing up (or only its +z when all_faces_up is false).
  int yaw_steps = 12;
  bool all_faces_up = true;
  // Each hypothesis is aligned with this many points of the largest segment for
  // coarse_iterations; the best `candidates` distinct results are refined with refine_points
  // points, verified and ranked; the winner is refined with all points.
  int coarse_points = 200;
  int coarse_iterations = 10;
  int candidates = 10;
  int refine_points = 400;
  // Rejection distance of the coarse alignment [m] (start, end).
  double coarse_start_distance = 0.03;
  double coarse_end_distance = 0.008;
  // Also try the best pose turned by quarter turns about the model's axes (near-symmetric proxies).
  bool twins = true;
  // While tracking, the detection also runs when the ICP corrects the prediction by more than
  // recheck_rotation_deg [deg] or recheck_translation [m], and every recheck_interval frames
  // (0: never), and when the tracked pose's free-space violation exceeds recheck_free_space (a
  // pose sliding into a wrong minimum starts to hide what the camera sees); its pose replaces the
  // tracked one when it scores switch_margin higher.
  double recheck_rotation_deg = 20.0;
  double recheck_translation = 0.03;
  int recheck_interval = 15;
  double recheck_free_space = 0.04;
  // The periodic and free-space checks are light: they refine only the motion model's seeds (the
  // prediction, the last pose, the displaced predictions) and the twins of the best, on the
  // predicted proxy's window, without the coarse hypotheses over the whole play area (a loss and a
  // large correction still search everything).
  bool light_rechecks = true;
  double switch_margin = 0.05;
  // ... and far_switch_margin higher when it is more than 45 deg from the tracked pose (a verified
  // pose does not turn that far in a frame: such a switch is to a twin, or from one). Continuity
  // outweighs a twin's lead of up to 0.3, the skin evidence's cap; the slide check and the twin
  // evidence decide trusted switches.
  double far_switch_margin = 0.3;
  // ... and within the detection, a candidate more than 45 deg from another wins over the one
  // nearer the prediction only when it scores far_switch_margin higher, once the track has been
  // measured for trusted_frames frames since its last loss (before that, a fresh detection may
  // still have picked a near-symmetric twin: switch_margin decides) and when the nearer one lies
  // within 45 deg of the prediction (continues the track; two poses both farther away, after a
  // proxy turned while it was lost, are ranked by switch_margin).
  int trusted_frames = 30;
  // Twin evidence (CUSUM, Page 1954): the best verified pose of the last detection that lies more
  // than 45 deg from its winner (the rival: a near-symmetric twin) is carried along with the track
  // and refined on every tracked frame; its score's excess over the tracked pose's, less
  // rival_drift, is summed (never below 0), and when the sum exceeds rival_threshold the rival
  // becomes the pose (0: off). A twin that explains the data a little better on many frames wins,
  // where one margin per check (far_switch_margin) either waits for a large difference or switches
  // on noise.
  // Once the track is trusted (trusted_frames), a check's pose more than 45 deg from the tracked
  // one does not replace it on one frame's score (far_switch_margin applies only before that):
  // it becomes the rival, and the twin evidence decides (with rival_threshold 0, the margin
  // decides as before trust). On a Mario take a light check switched into the half-turn twin on
  // one frame that scored 0.16 above a pose the hand had degraded (51 frames lost to the twin).
  // Besides the prediction and the last pose, the prediction shifted by +-seed_shift [m] along the
  // table's normal and turned by +-seed_turn_deg [deg] about the table's x and y axes through the
  // model's centre are refined as candidates (0: not).
  double seed_shift = 0.012;
  double seed_turn_deg = 10.0;
  // Slide check, on tracked frames: the tracked pose shifted by +-seed_shift along the table's
  // normal is refined (as the rival is) and replaces it when it scores switch_margin higher. Seen
  // from the side under the hand the Soldier's data hardly constrains its height, the
  // motion model's prediction carries one frame's 5 mm of noise on, and the motion prior holds
  // the pose there: it climbed 20 mm in three frames and stayed (or a check took its half-turn
  // twin, equally high); the displaced seeds of the periodic check came up to 15 frames late.
  bool slide_check = true;
  // ... on the frames whose score falls more than slide_drop below the track's recent score (an
  // exponential average over the last ~10 measured frames; 0: every frame). A slide costs the
  // score (the true pose scored 1.21-1.23 on the take where the slid one fell from 1.16 to 1.0),
  // and the check costs two refinements, 30 % of the frame's time when run on every frame.
  double slide_drop = 0.02;
  double rival_drift = 0.03;
  double rival_threshold = 0.25;
  // Real recordings (the object among others on a table): a detection after a loss tries up to
  // model_segments segments, largest first, each no larger than the model's bounding sphere
  // (diameter plus segment_slack [m]), on that segment's points alone, and keeps the verified
  // pose that scores best with the share of the model's visible surface the depth confirms
  // (0: the proxy's rule, the largest segment of the play volume is the proxy).
  int model_segments = 0;
  double segment_slack = 0.02;
  // ... and tracking from a prediction scores a pose on the predicted model's own segments of its
  // window: a segment is kept when at least own_segment_share of its points lie within
  // own_segment_distance [m] of the model's surface at the predicted pose (0: off, the whole
  // window counts, the proxy's rule: the hand is no segment of its own there). The detection
  // among segments scores on its segment's points alone; the window also holds whatever lies in
  // front of or behind the object, and on YCB-Video video 0000 the foam brick in front of the mug
  // held the mug's true pose at an inlier share of 0.27 < 0.5: lost on every frame, and each
  // detection took another pose.
  double own_segment_share = 0.0;
  double own_segment_distance = 0.01;
  // After a loss, the last measured pose stays a seed of the detection (with its displaced
  // variants, and as the reference continuity breaks ties against) for this many frames (0: the
  // loss forgets it). A loss is mostly one frame that failed its verification under the hand, and
  // the proxy is still near where it was; the detection from the coarse hypotheses alone needs a
  // segment of min_points, which a hand over the proxy breaks into pieces.
  int reacquire_frames = 30;
  // A trusted track (trusted_frames) whose pose fails its verification does not leave for a pose
  // more than 135 deg from the prediction that the detection verifies (a half-turn twin): that
  // pose becomes the rival, and the frame is predicted (extrapolated, up to
  // verification.max_predicted_frames). Without this
  // the verification alone switches a trusted track into its twin, which the twin evidence exists
  // to prevent: on structured-light frames under the hand the true pose's inlier share falls just
  // under min_inlier_share while the twin's does not.
  bool hold_trusted = true;
  // A re-acquisition (reacquire_frames) within reacquire_trust_frames frames of the loss continues
  // the track it lost: when that track was trusted, the detection ranks as for a trusted track
  // (far_switch_margin, hold_trusted), so a short loss is no door into the twin (0: never). On
  // structured-light frames at 0.85 m, Mario's take 2 lost frame 263 at an inlier share of 0.747
  // and the re-detection on the next frame took the half-turn twin for 157 frames; Soldier takes
  // lost two frames under the hand and re-detected the twin (docs/tracker.md, "Trust across
  // short gaps"). A proxy may turn while it is lost, and the hold refuses a pose more than 135 deg
  // from the one before the loss: the stories' fastest turn is 120 deg in 4 frames (a loss of 3
  // frames and the frame after it) and 135 deg in 5. A proxy hidden (too few points, predicted)
  // for up to as many frames keeps the trust too; predicted frames followed by lost ones are one
  // gap, and the trust spans at most this many frames of it in all.
  int reacquire_trust_frames = 3;

  template <class V>
  void VisitFields(V& v) {
    v("yaw_steps", yaw_steps);
    v("all_faces_up", all_faces_up);
    v("coarse_points", coarse_points);
    v("coarse_iterations", coarse_iterations);
    v("candidates", candidates);
    v("refine_points", refine_points);
    v("coarse_start_distance", coarse_start_distance);
    v("coarse_end_distance", coarse_end_distance);
    v("twins", twins);
    v("recheck_rotation_deg", recheck_rotation_deg);
    v("recheck_translation", recheck_translation);
    v("recheck_interval", recheck_interval);
    v("recheck_free_space", recheck_free_space);
    v("light_rechecks", light_rechecks);
    v("switch_margin", switch_margin);
    v("far_switch_margin", far_switch_margin);
    v("trusted_frames", trusted_frames);
    v("seed_shift", seed_shift);
    v("seed_turn_deg", seed_turn_deg);
    v("slide_check", slide_check);
    v("slide_drop", slide_drop);
    v("rival_drift", rival_drift);
    v("rival_threshold", rival_threshold);
    v("model_segments", model_segments);
    v("segment_slack", segment_slack);
    v("own_segment_share", own_segment_share);
    v("own_segment_distance", own_segment_distance);
    v("reacquire_frames", reacquire_frames);
    v("hold_trusted", hold_trusted);
    v("reacquire_trust_frames", reacquire_trust_frames);
  }
  void Validate(const std::string& prefix) const;
};

struct VerificationOptions {
  // A frame needs this many segmented points to be measured [points]; fewer: predicted.
  int min_points = 60;
  // Inlier share (of the segmented points, within icp.inlier_distance) at least, and inlier RMS
  // point-to-plane residual at most [m].
  double min_inlier_share = 0.75;
  double max_rms = 0.004;
  // Free space: of the model's camera-facing samples with a depth reading, at most this share may
  // show a depth more than free_space_margin [m] behind the model.
  double max_free_space_violation = 0.12;
  double free_space_margin = 0.015;
  // The proxy's centre must lie within the play area grown by this margin [m] and below
  // segmentation.max_height.
  double play_area_margin = 0.06;
  // The proxy cannot reach into the table: a pose whose model lies more than max_penetration [m]
  // below the estimated table plane is rejected (the Soldier's upside-down twin, standing on its
  // head inside the table, explains the visible body as well as the true pose does when the hand
  // hides the head).
  double max_penetration = 0.01;
  // Frames a pose may be extrapolated without a measurement before it is reported lost.
  int max_predicted_frames = 10;
  // Skin-coloured points help the fit only within this distance of the model [m].
  double skin_distance = 0.004;
  // Colour consistency (needs a model with face colours): skin-coloured points match only model
  // surfaces that can look skin-coloured (the Soldier's head and rifle), the other points only
  // surfaces that can look otherwise (track/point_to_plane_icp.h, sample_matches).
  bool colour_matching = true;
  // Candidate poses are ranked by the share of the segmented points they explain plus the
  // skin-coloured points on skin-coloured model surfaces (per segmented point), but the latter
  // count up to this share only: the hand holding the proxy supplies any number of skin points
  // near it, and a twin that turns a skin-coloured face (Mario's) into the hand would otherwise
  // outscore the true pose; a skin-coloured head or rifle (the Soldier's) is a smaller share.
  double max_skin_evidence = 0.3;
  // At most this many segmented points enter the ICP (evenly subsampled) [points].
  int max_points = 1500;

  template <class V>
  void VisitFields(V& v) {
    v("min_points", min_points);
    v("min_inlier_share", min_inlier_share);
    v("max_rms", max_rms);
    v("max_free_space_violation", max_free_space_violation);
    v("free_space_margin", free_space_margin);
    v("play_area_margin", play_area_margin);
    v("max_penetration", max_penetration);
    v("max_predicted_frames", max_predicted_frames);
    v("skin_distance", skin_distance);
    v("colour_matching", colour_matching);
    v("max_skin_evidence", max_skin_evidence);
    v("max_points", max_points);
  }
  void Validate(const std::string& prefix) const;
};

// The tracker's ICP: IcpOptions' defaults with the motion prior on (2 deg, 3 mm), which only the
// frame-to-frame ICP from the prediction uses; the detection's and the scores' ICPs run without.
inline IcpOptions TrackingIcpOptions() {
  IcpOptions icp;
  icp.prior_rotation_deg = 2.0;
  icp.prior_translation = 0.003;
  return icp;
}

struct ProxyTrackerOptions {
  TablePlaneOptions table;
  SegmentationOptions segmentation;
  ProxyModelOptions model;
  IcpOptions icp = TrackingIcpOptions();
  ProjectiveOptions projective;
  MotionOptions motion;
  DetectionOptions detection;
  VerificationOptions verification;
  // The colour check among the depth's equivalent poses (track/appearance.h; off by default, and
  // then without effect: it needs SetAppearanceModel).
  AppearanceOptions appearance;
  // The low-pass on the reported poses (track/pose_filter.h; off by default).
  PoseFilterOptions output_filter;

  template <class V>
  void VisitFields(V& v) {
    v("table", table);
    v("segmentation", segmentation);
    v("model", model);
    v("icp", icp);
    v("projective", projective);
    v("motion", motion);
    v("detection", detection);
    v("verification", verification);
    v("appearance", appearance);
    v("output_filter", output_filter);
  }
  void Validate(const std::string& prefix) const;
};

struct TrackFrameResult {
  int index = 0;
  double timestamp = 0.0;
  TrackStatus status = TrackStatus::kLost;
  // camera_T_proxy of the depth camera; meaningful unless lost.
  Rigid3 camera_T_proxy;
  // The pose came from a global detection (first frame, or recovery after a loss).
  bool detected = false;
  // Why the frame is predicted or lost, or what was wrong with it ("" when tracked).
  std::string reason;
  int points = 0;       // segmented proxy points
  int skin_points = 0;  // skin-coloured foreground points
  double inlier_share = 0.0;
  double rms = 0.0;                   // [m]
  double free_space_violation = 0.0;  // share
  int iterations = 0;
  // Wall-clock time the run spent on this frame [s]: tracking (or the detection) and the slider,
  // not reading the frame. Written by RunTracking; a timing, so it differs between runs.
  double seconds = 0.0;
};

class ProxyTracker {
 public:
  // `model` is the proxy's mesh in its own frame (InputError naming `model_name` when invalid).
  // Options are validated (prefix "tracker").
  ProxyTracker(const TriangleMesh& model, const std::string& model_name, const TrackSetup& setup,
               const ProxyTrackerOptions& options);
  ~ProxyTracker();

  // Starts the track at a known pose (the ground truth's first pose of a recording, when a run
  // asks for it): the next Track() refines this pose as a prediction instead of detecting the
  // object; a loss after that detects as usual.
  void Initialize(const Rigid3& camera_T_proxy);

  // The coloured model of the appearance check (AppearanceOptions; in the model's frame). Without
  // one, or with appearance.margin 0, detections rank by the depth alone.
  void SetAppearanceModel(std::shared_ptr<const AppearanceModel> appearance);

  // Tracks one frame. Never throws for a bad frame: a frame of the wrong size, with other
  // intrinsics than the first, without depth or without a table is lost with the reason. With
  // output_filter.enabled the reported pose is the filtered one (restarted at a detection and
  // after a loss).
  TrackFrameResult Track(const RgbdFrame& frame);
  // The frame could not be read (FrameSource::frame_error): lost with that reason.
  TrackFrameResult Unreadable(const RgbdFrame& frame, const std::string& error);

  // Refines `camera_T_proxy` against the frame last passed to Track() (the same frame) and scores
  // it as the tracker ranks candidate poses (for diagnostics and tests): returns the refined pose
  // with its inlier share, residual, free-space violation, explained share and score.
  struct PoseScore {
    Rigid3 camera_T_proxy;
    double inlier_share = 0.0, rms = 0.0, free_space_violation = 0.0, explained = 0.0, score = 0.0;
    bool good = false;
    // The appearance model's agreement with the colour image at the refined pose, as the
    // detection computes it (nullopt when the check is off: no model or appearance.margin 0; or
    // with too few samples seen).
    std::optional<double> appearance;
  };
  PoseScore ScorePose(const RgbdFrame& frame, const Rigid3& camera_T_proxy) const;

  // The table frame in the depth camera (from the estimated plane); nullopt before the first
  // frame with a plane.
  const std::optional<Rigid3>& camera_T_table() const { return camera_T_table_; }
  const std::optional<TablePlane>& table_plane() const { return table_plane_; }
  const ProxyModel& model() const { return *model_; }
  const Segmentation& last_segmentation() const { return segmentation_; }

 private:
  struct Candidate;
  bool EnsureTable(const RgbdFrame& frame, std::string* why);
  // data_ and scored_ from segmentation_.
  void PrepareData();
  // detection_scratch_: data_ subsampled to about refine_points scored points (and the extra
  // points in proportion); returns how many are scored.
  size_t PrepareMediumData();
  // The twin evidence (DetectionOptions::rival_threshold): sets the rival (nullopt: keeps the old
  // one, or forgets it when reset_evidence), resetting the evidence when asked or when it is
  // another twin.
  void SetRival(const std::optional<Rigid3>& proxy_T_rival, bool reset_evidence);
  // Refines the rival on this frame, adds its evidence, and replaces *chosen by it when the
  // evidence suffices (returns true then).
  bool WeighRival(const RgbdFrame& frame, Candidate* chosen);
  // The slide check (DetectionOptions::slide_check): replaces *chosen by its better displaced
  // refinement along the table's normal (returns true then).
  bool CheckSlide(const RgbdFrame& frame, Candidate* chosen);
  // Refines camera_T_start on the detection's subsample, then for two iterations on all of this
  // frame's data, and verifies it (the rival's and the slide check's refinement).
  Candidate RefineOnFrame(const RgbdFrame& frame, const Rigid3& camera_T_start);
  // Track's steps. Lose: the frame is lost (the motion, the rival and the recent score reset).
  // Track() before the output filter.
  TrackFrameResult TrackUnfiltered(const RgbdFrame& frame);
  TrackFrameResult Lose(TrackFrameResult result, const std::string& reason);
  // What makes the frame unusable (wrong size, other intrinsics, no depth), or "".
  std::string FrameProblem(const RgbdFrame& frame) const;
  // segmentation_, data_ and result's point counts, within `window` when given; with `own` (the
  // predicted camera_T_proxy) and DetectionOptions::own_segment_share > 0, only the segments that
  // lie on the model there.
  void SegmentFrame(const RgbdFrame& frame, const ImageRect* window, TrackFrameResult* result,
                    const Rigid3* own = nullptr);
  // Drops from segmentation_ the components of which less than own_segment_share of the points
  // lie within own_segment_distance of the model at camera_T_proxy.
  void KeepOwnSegments(const Rigid3& camera_T_proxy);
  // The ICP from the prediction, verified, and the detection's check when the correction is
  // large, the free space grows or the periodic check is due; nullopt (with *why) when no pose
  // verifies. *windowed becomes false when the check segments the whole play area.
  std::optional<Candidate> TrackFromPrediction(const RgbdFrame& frame, const Rigid3& predicted,
                                               bool* windowed, TrackFrameResult* result,
                                               std::string* why);
  // The detection after a loss (or on the first frame): a verified pose, or nullopt with *why.
  // *held: the detection found only a twin of a trusted track (DetectionOptions::hold_trusted).
  std::optional<Candidate> DetectAfterLoss(const RgbdFrame& frame,
                                           const std::optional<Rigid3>& predicted,
                                           TrackFrameResult* result, std::string* why,
                                           bool* held);
  // The chosen pose reported (projectively refined), measured by the motion model, and the
  // background learnt around it; `slid`: moved by the slide check (no motion).
  void ReportTracked(const RgbdFrame& frame, const Candidate& chosen, bool slid,
                     TrackFrameResult* result);

  // The global detection; `predicted` (the motion model's pose, when there is one) breaks ties.
  // `light`: only the motion model's seeds and the twins, no coarse hypotheses.
  std::optional<Candidate> Detect(const RgbdFrame& frame, const std::optional<Rigid3>& predicted,
                                  bool light);
  // Detect's steps: the coarse alignment's ICP options; the coarse results' order, best first;
  // whether candidate a ranks before b; a refined pose verified and ranked (Weigh), once per
  // distinct pose (WeighDistinct); an ICP on the detection's subsample; the motion model's seeds;
  // the best pose's quarter-turn twins; the rival of the winner among the verified poses.
  struct DetectionRanking;
  IcpOptions CoarseIcpOptions() const;
  std::vector<size_t> RankCoarse(const RgbdFrame& frame, const std::vector<IcpResult>& coarse_results,
                                 size_t coarse_scored) const;
  bool Better(const Candidate& a, const std::optional<Candidate>& b,
              const std::optional<Rigid3>& predicted) const;
  void Weigh(const RgbdFrame& frame, const IcpResult& refined, DetectionRanking* ranking) const;
  void WeighDistinct(const RgbdFrame& frame, const IcpResult& refined,
                     DetectionRanking* ranking) const;
  IcpResult RefineOnMedium(const Rigid3& proxy_T_camera, const IcpOptions& icp,
                           size_t medium_scored) const;
  std::vector<Rigid3> MotionSeeds(const std::optional<Rigid3>& predicted) const;
  void WeighTwins(const RgbdFrame& frame, const IcpOptions& coarse_icp, size_t medium_scored,
                  DetectionRanking* ranking) const;
  void SetDetectionRival(const RgbdFrame& frame, DetectionRanking* ranking);
  // The appearance check (AppearanceOptions): among ranking's verified poses within margin of the
  // best's score, the one whose colours agree best replaces the best when it agrees min_gain
  // better. A pose's agreement, when the check is on (the one gate: a model and margin > 0;
  // nullopt otherwise, or too few samples); verified[i]'s, computed once per detection.
  void ChooseByAppearance(const RgbdFrame& frame, DetectionRanking* ranking) const;
  std::optional<double> AppearanceAgreement(const RgbdFrame& frame,
                                            const Rigid3& camera_T_proxy) const;
  std::optional<double> VerifiedAgreement(const RgbdFrame& frame, size_t i,
                                          DetectionRanking* ranking) const;
  // The detection among the model-sized segments (DetectionOptions::model_segments); leaves
  // segmentation_ and data_ holding the winner's segment.
  std::optional<Candidate> DetectAmongSegments(const RgbdFrame& frame,
                                               const std::optional<Rigid3>& predicted);
  // The coarse hypotheses' alignments (orientations about the table normal, placed at the largest
  // segment); *scored: how many of their points are scored. Empty without a large enough segment.
  std::vector<IcpResult> CoarseHypotheses(const IcpOptions& coarse_icp, size_t* scored) const;
  Candidate Verify(const RgbdFrame& frame, const IcpResult& icp) const;
  // Of the model's camera-facing sparse samples with a depth reading: the share whose depth the
  // frame confirms (within free_space_margin) and the share it sees behind (free space).
  // Also how deep the model reaches below the table plane [m] (0 when it does not).
  struct Visibility {
    double explained = 0.0;
    double violation = 0.0;
    double penetration = 0.0;
  };
  Visibility ModelVisibility(const RgbdFrame& frame, const Rigid3& camera_T_proxy) const;
  // The image of the model's bounding sphere grown by `margin` [m] (and 4 px).
  ImageRect ProxyImage(const Rigid3& camera_T_proxy, double margin) const;

  ProxyTrackerOptions options_;
  TrackSetup setup_;
  std::unique_ptr<ProxyModel> model_;
  std::shared_ptr<const AppearanceModel> appearance_;
  Segmenter segmenter_;
  Segmentation segmentation_;
  std::optional<PinholeIntrinsics> intrinsics_;
  std::optional<TablePlane> table_plane_;
  std::optional<Rigid3> camera_T_table_;
  // Motion state: the motion model (set in the constructor) and the frames predicted since.
  std::optional<MotionModel> motion_;
  // The reported poses' low-pass (used only when options_.output_filter.enabled).
  PoseFilter output_filter_;
  int predicted_frames_ = 0;
  int frames_since_detection_ = 0;
  int tracked_frames_ = 0;  // measured frames since the last loss
  // Scratch: the subsampled segmented points (the first scored_), then the skin points.
  std::vector<Eigen::Vector3f> data_;
  // The scored points of data_ off the outline band (segmentation.outline_span; empty when off or
  // when fewer than verification.min_points): what Verify judges a pose by.
  std::vector<Eigen::Vector3f> interior_;
  std::vector<Eigen::Vector3f> detection_scratch_;
  // Per model sample: which data it may match (kMatchesScored | kMatchesExtra); empty: all.
  std::vector<uint8_t> sample_matches_;
  // The rival of the tracked pose (proxy_T_rival, in the proxy's frame), the rival the last
  // detection found (proxy_T_rival relative to its winner) and the evidence for it.
  std::optional<Rigid3> proxy_T_rival_;
  std::optional<Rigid3> detection_rival_;
  double rival_evidence_ = 0.0;
  // The last measured pose before the loss, the frames lost since and the measured frames before
  // it (DetectionOptions::reacquire_frames, reacquire_trust_frames); nullopt while tracking or
  // once too old.
  std::optional<Rigid3> reacquire_pose_;
  int reacquire_age_ = 0;
  int reacquire_tracked_frames_ = 0;
  int reacquire_predicted_frames_ = 0;  // frames predicted just before the loss: the same gap
  // The exponential average of the tracked poses' scores (the slide check's reference); nullopt
  // after a loss.
  std::optional<double> recent_score_;
  // options_.icp without the motion prior (detection, scoring).
  IcpOptions search_icp_;
  size_t scored_ = 0;
};

}  // namespace mmh::track
