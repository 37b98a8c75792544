// The real lens's brightness across the frame, imposed on the models that only approximate it.
//
// A uniformly bright surface photographed through a lens falls off towards the frame's corners as
// the lens's relative illumination: the projected solid angle of the real entrance pupil (which
// grows off axis in a retrofocus design), clipped by the real clear apertures, over the image area
// a pixel's patch of scene maps to. The exact model's traced rays carry the first two, but the scatter
// weighs a footprint's coverage by the image area of its pixel's chief rays (ImageAreaTable), while a
// vignetted beam's light lands about its centroid, which moves off the chief ray where the clear
// apertures cut the beam: the image area the light really spreads over is the centroids' (a pixel's
// brightness is light over coverage). Through lentil's Primoplan at f/1.5 (48 x 32 mm frame) that made
// the exact model 0.015 of the centre too bright where the vignetting sets in and 0.040 too dark at the
// corner; at f/8 0.041 too bright in the corner. Two independent brute-force estimates agree with the
// ground truth there within 0.004 (a film point's projected solid angle of passing directions, and a
// point's passing flux over its light centroids' image area). So the exact model takes the table too:
// its factor is 1 where the centroid is the chief ray's, and makes the wall agree with the truth
// within 0.004 on that lens (radial profile; 0.006 on the test's strip). The first-order models (paraxial, Seidel) take the
// solid angle of the paraxial pupil and first-order images of the clear apertures (discs), the poly
// model a fit's weights, and the thin model of a lens (its EFL and f-number) nothing at all: it was
// flat to the corners where the double Gauss of issue 12 at f/2 falls to 0.65. On a retrofocus
// framed to 50 deg (lentil 0005) the paraxial model fell to 0.05 of the centre at the frame's side
// where the truth has 0.31, the Seidel model's discs left a dark ring at 40 deg and a flat 0.72
// beyond it, and poly was 12 % dark at mid-field.
//
// So the first-order models' discs are widened where they pass far less of the pupil than the real
// lens's clear apertures do (relative to the axis; below 0.8 of it, fully below 0.4): on that
// retrofocus beyond 40 deg they stopped every ray where the real lens passes 60 % of the axis's
// light, and the picture there was whatever the hidden-surface fill made of its neighbours. Each
// disc's radius is scaled about its centre by the one factor that makes the discs pass the real
// lens's share (found at the nodes by bisection); the cat's eye keeps the first-order discs'
// centres, so its shape is an approximation there.
//
// And each footprint's light is scaled by R_real / R_model, R a uniform surface's brightness
// relative to the axis's. R_model is the model's own at the source's field and depth (with its
// widened discs): B = L / A, with L the light a point's beam passes (the mean ray weight over the
// pupil where the rays pass, measured on a fine polar mesh as the renderer measures it,
// MappedPupilTable::passing_light) and A the image area its pixel maps to (ImageAreaTable). R_real
// is the real lens's brightness at the output pixel where the model's light lands on average,
// measured at the film as the ground truth measures it (`lensmith scene render --lens`, LensCamera:
// a film point's irradiance is the mean over the pupil of its rays' weights where they pass). So a
// uniform surface is as bright across the frame as through the real lens, whatever the model's
// distortion (the paraxial model has none), and at every depth (every ray that reaches a film point
// from a uniform surface brings the same radiance, however far the surface is). Near a vignetting
// cliff a beam's passing sliver lands well outside its chief ray (lentil 0005 at 55 deg: 3.7 px out
// on a 192 px frame): the model's light is placed where it lands, and takes the real lens's
// brightness there. A lone highlight carries the real lens's light times the model's image area
// over the lens's (1 to 3 % apart where the Seidel model's distortion is the lens's within its third
// order). The footprint's shape (cat's eye, aberrations) stays the model's own.
//
// The real brightness was first taken from the object side, as R_model is: the real beams' light
// over the image area of their chief rays, stretched to where their light lands. That stretch moved
// with the light's centroid, which a 0.1 px error at the frame's edge turned into 1-2 %: the
// first-order models came out 0.011-0.033 of the centre brighter than the truth at the frame's edge
// on lentil 0001, 0009 and 0010 wide open, where the exact model is within 0.012.
//
// Tabulated along the field radius (the lens is round: MappedPupilTable::round_lens) at kFieldNodes
// radii and kDepthNodes inverse depths across the picture's, read by linear interpolation.
#pragma once

#include <vector>

#include "lensmith/camera/aperture.h"
#include "lensmith/camera/ray_model.h"
#include "image_area_table.h"
#include "pupil_mesh_table.h"

namespace lensmith::render_detail {

class IlluminationTable {
 public:
  static constexpr int kFieldNodes = 48;
  static constexpr int kDepthNodes = 4;
  // A footprint's light is scaled by at most this: where the model passes almost nothing (its discs
  // stop a beam the real lens passes), its shape is not the lens's either.
  static constexpr double kMaxFactor = 8.0;

  // Whether the table applies: the paraxial, Seidel or poly model of a round lens (no mirrors, tilts
  // or anamorphic squeeze; MappedPupilTable::round_lens), or the thin model that stands for one
  // (Camera::real_lens; an ideal thin lens, as CG cameras have it, keeps no falloff), vignetting on,
  // an aperture that is not a picture.
  // `exact_too`: the exact model too, for the methods that spread a pixel's light over its chief
  // rays' image area while a vignetted beam's light lands about its centroid (the scatter, and the
  // PSF tables of ewa and gather; the header says why). Through lentil's Primoplan at f/1.5 their
  // exact walls were up to 0.040 and 0.026 of the centre off the truth, now within 0.004 and 0.006.
  // (The light field's exact wall, 0.013 off without the table, came out 0.030 off with it.)
  static bool applies(const RayModel& model, const Aperture& aperture, bool vignetting, bool exact_too = false);
  // The table where it applies, with the model's own image areas and the light mesh; empty (every
  // factor 1) where it does not. `thin_only`: only for the thin model of a real lens (methods that
  // take the other models' brightness from their own ray weights); `exact_too` as for applies.
  static IlluminationTable where_applies(const RayModel& model, const Aperture& aperture, bool vignetting, int margin_px,
                                         double w_min, double w_max, int threads, bool thin_only = false, bool exact_too = false);

  // Every factor 1.
  IlluminationTable() = default;
  // For `model`'s frame and `margin_px` beyond it, inverse depths w_min..w_max (1/mm). `fine` is the
  // polar mesh the light is measured on; `areas` the model's image areas. Empty where either model
  // finds no light on the axis.
  IlluminationTable(const RayModel& model, const PupilMesh& fine, const ImageAreaTable& areas, int margin_px, double w_min,
                    double w_max, int threads);
  bool empty() const { return depths_.empty(); }
  // The factor on the light of a source at `point`.
  float factor(const ScenePoint& point) const;
  // The model's discs of `point` (RayModel::clip_discs) widened where they pass less than the real
  // lens; whether they were.
  bool widen(const ScenePoint& point, std::vector<PupilDisc>& discs) const;
  // Where `point`'s discs are widened: the share of the pupil they pass, interpolated between the
  // nodes' (which the light factor was measured with); 0 where they are not. The share of discs
  // widened by an interpolated factor is not the interpolated share, and light scaled by the factor
  // alone rippled by 3 % with the nodes' spacing: a footprint's light is taken at this share instead
  // of its own (FootprintScatter::plan).
  double widened_share(const ScenePoint& point) const;
  // Whether the model's chief rays move outwards with the field up to `point`'s field radius (a
  // Seidel polynomial folds back beyond the field it was made for, a fisheye's at 60 deg, and lands
  // such points near the frame's centre); false where the table is empty.
  bool unfolded(const ScenePoint& point) const;

 private:
  // One inverse depth's nodes, at field radii (tangent of the field angle) i * step_.
  struct Depth {
    std::size_t unfolded = 0;            // nodes [0, unfolded] land further out than the one before
    std::vector<double> disc_scale;      // the discs' radius factor (>= 1)
    std::vector<double> model_share;     // the share of the pupil the model passes with them
    std::vector<double> model_relative;  // the model's B / B(axis), or -1 where its chief ray lands nowhere
    std::vector<double> model_rho_px;    // where the model's light lands on average (its chief ray where none
                                         // passes), output px from the axis's
    std::vector<double> factor;          // the light factor at each node
  };
  double node_factor(const Depth& d, std::size_t i) const;
  // Interpolates `of` over the nodes at field radius `radius` and inverse depth w.
  template <typename Of>
  double at(const ScenePoint& point, Of&& of) const;

  // The real lens's brightness at the film (the irradiance from a uniform surface relative to the
  // frame centre's) at output radii (px) from the frame's centre, the same at every depth.
  std::vector<double> real_rho_px_;
  std::vector<double> real_relative_;
  double step_ = 1.0;  // tangent per node
  double w0_ = 0.0, dw_ = 1.0;
  std::vector<Depth> depths_;
  bool widened_ = false;  // some node's discs are widened
};

}  // namespace lensmith::render_detail
