// frontend: options of masks, corner detection and KLT tracking (reference values in
// reference-behaviour §3.1 and §6.5).
#pragma once

#include <nlohmann/json.hpp>

namespace nrslam {

struct MaskOptions {
  int border_px = 8;              // image border excluded, px
  int bright_threshold = 240;     // grey level above which a pixel is a specular highlight (255 = off)
  int bright_margin_px = 6;       // highlights also invalidate this many px around them
  int erosion_px = 5;             // the combined valid area is eroded by this, px
  // Regions that never change over a sequence (an on-screen display, a black border without a
  // mask): found from this many frames spread over each window of the sequence and left out of
  // that window's frames, since a corner there would be tracked as a point that moves with the
  // camera. 0 = off.
  int static_frames = 24;
  int static_max_change = 4;      // a static pixel is within this many grey levels of its median in 9 of 10 frames
  int static_min_area_px = 64;    // smaller static patches are ignored (a few px of flat tissue)
  double static_min_edge = 16;    // grey levels per px: a static patch without so strong an edge is flat tissue
  int static_margin_px = 10;      // px around a static region left out too (about half the KLT window)
  // More of the image than this static (margin included) is a still view, not a display:
  // then nothing is left out.
  double static_max_fraction = 0.8;
  // s: a sequence spanning less is not checked. Over a short span tissue the camera barely moves
  // past stays put as a display does (intact renderings at 160x120 to 640x480 lost up to 84 %
  // of the image to the check within 2.5 s, none from 3 s on).
  double static_min_seconds = 3.5;
  // s: a longer sequence is looked at in windows this long, each half a window after the last,
  // so that a display shown for a while only is found (in the windows it fills, at least 9 of
  // 10 of their frames). At least static_min_seconds.
  double static_window_seconds = 8;
  // The fewest frames that can tell a static region: one in ten may stray (a dropout, a flash).
  static constexpr int kMinStaticFrames = 10;
  void Check() const;
};

struct FeatureOptions {
  double min_eigenvalue = 7.7e-5;  // Shi–Tomasi score threshold, OpenCV cornerMinEigVal units (block 3, Sobel 3)
  int nms_radius_px = 7;           // a corner must be the maximum within ±radius
  int exclusion_radius_px = 15;    // no new corner within this distance of an existing track
  int max_features = 800;          // cap on corners per detection (strongest first); bounds the map size
  void Check() const;
};

struct KltOptions {
  int window_px = 21;              // patch side, px (odd)
  int levels = 4;                  // pyramid levels. The reference uses 5, but on levels 3-4 a 21 px window
                                   // spans 168-336 px, sees the light field more than the texture, and under
                                   // local light changes 28 % of tracks went astray (3 levels: none). 3 levels
                                   // still reach ±70 px, beyond any keyframe-to-frame motion at 30 fps.
  int max_iterations = 10;         // per level
  double epsilon_px = 0.01;        // stop when the step is shorter, px
  double min_eigenvalue = 1e-4;    // reject untextured patches; OpenCV LK's minEigThreshold scale
  double max_displacement_px = 10; // per level, from where the level started; beyond it the track is lost
  bool affine_refinement = true;   // finish on level 0 with an affine warp (rotation/scale between reference and now)
  int affine_iterations = 2;       // Gauss–Newton from the converged translation needs few
  // SSIM thresholds per use, on the patch with the fitted gain and bias plane undone. The
  // reference's 0.7 / 0.5 / 0.75 were for raw patches. Measured after the fit: correct
  // matches keep >= 95.8 % at 0.75 in every warp and light test; deliberately wrong ones
  // score 0.68 median, and 68 % are rejected at 0.75, 98 % at 0.9.
  double ssim_tracking = 0.75;
  double ssim_initialisation = 0.6;
  double ssim_reassociation = 0.9;  // a re-found point has no track history: be strict
  // The SSIM above also scores the fitted trend plane, which the correction matches by
  // construction; this gate scores the texture alone: the correlation of reference and window
  // with their mean and linear trend removed, in [-1, 1] (-1: off). Pure noise scores ~0.
  double min_texture_correlation = -1;
  void Check() const;
};

// How a pixel's brightness is read for the shading prior (frontend/shading.h); the prior
// itself is off unless initialisation.shading_weight or mapping.new_point_shading_weight is set.
struct ShadingOptions {
  double gamma = 2.2;  // the camera's response: linear brightness = (grey level / 255)^gamma
  int patch_px = 5;    // a pixel's brightness: the mean over the valid pixels of a (2·this + 1)² box
  void Check() const;
};

struct FrontendOptions {
  MaskOptions masks;
  FeatureOptions features;
  KltOptions klt;
  ShadingOptions shading;
  void Check() const {
    masks.Check();
    features.Check();
    klt.Check();
    shading.Check();
  }
};

NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(MaskOptions, border_px, bright_threshold, bright_margin_px, erosion_px,
                                                static_frames, static_max_change, static_min_area_px, static_min_edge,
                                                static_margin_px, static_max_fraction, static_min_seconds,
                                                static_window_seconds)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(FeatureOptions, min_eigenvalue, nms_radius_px, exclusion_radius_px,
                                                max_features)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(KltOptions, window_px, levels, max_iterations, epsilon_px,
                                                min_eigenvalue, max_displacement_px, affine_refinement, affine_iterations, ssim_tracking,
                                                ssim_initialisation, ssim_reassociation, min_texture_correlation)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(ShadingOptions, gamma, patch_px)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(FrontendOptions, masks, features, klt, shading)

}  // namespace nrslam
