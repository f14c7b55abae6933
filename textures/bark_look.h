#pragma once
/// What a species' bark keys describe, whichever kind reads them: the bark pattern, its
/// colours, and the branch bark ridge drawn over PCM seams and as arcs over branches.
/// `tree.bark` (kind: tree) and a `{bark: {...}}` texture (kind: blob) both read it with
/// sprig::readBarkLook (model/bark_keys.h), so the keys, defaults and ranges exist once.

#include <optional>

#include "core/types.h"
#include "textures/procedural.h"
#include "textures/ridge.h"

namespace sprig::textures {

/// The bark keys' values. Colours left unset take the kind's own defaults (resolved()).
struct BarkLook {
  /// The pattern (furrows, warp, braid, peel, lenticels, ...). Its colours are ignored:
  /// resolved() fills them from the optional colours below.
  BarkOptions pattern;
  std::optional<Vec3> ridgeColor, furrowColor, youngColor, lenticelColor, peelColor;
  /// Bark multiplied by 1 − ridgeDarkening·contact³ (blobtree::Attributes::contact: 1 on
  /// the PCM seam, 0 a propagation width away): the compressed bark of the branch bark ridge.
  double ridgeDarkening = 0.0;
  /// Folds of bunched bark across the ridge's band, parallel to the seam and crowding toward
  /// it (RidgeOptions::lines; darkened by ridgeDarkening); 0: none.
  int ridgeLines = 0;
  /// Shading relief of the ridge (RidgeOptions::relief: the normal tilts by a slope of
  /// 1.5·ridgeRelief on the crest's flanks); 0: none. The geometry stays PCM's.
  double ridgeRelief = 0.0;
  /// The branch bark ridge as an arc over each branch beside a leader, curving down both
  /// sides of it (RidgeArcs); off while darkening and relief are 0. ridgeArc.height > 0
  /// also raises the bark along the arc's crest (geometry: organisms::raisedRidgeArc).
  RidgeArcOptions ridgeArc;

  /// The pattern with its colours: an unset ridge colour is `ridge`, an unset furrow colour
  /// `furrow`, an unset young colour the ridge colour, unset lenticel and peel colours
  /// BarkOptions' defaults.
  BarkOptions resolved(const Vec3& ridge, const Vec3& furrow) const {
    BarkOptions o = pattern;
    o.ridgeColor = ridgeColor.value_or(ridge);
    o.furrowColor = furrowColor.value_or(furrow);
    o.youngColor = youngColor.value_or(o.ridgeColor);
    o.lenticelColor = lenticelColor.value_or(BarkOptions{}.lenticelColor);
    o.peelColor = peelColor.value_or(BarkOptions{}.peelColor);
    return o;
  }
  /// The ridge shading's options (wanderScale and seed: RidgeOptions' defaults).
  RidgeOptions ridge() const {
    RidgeOptions r;
    r.darkening = ridgeDarkening;
    r.lines = ridgeLines;
    r.relief = ridgeRelief;
    return r;
  }
  /// True when the arcs change colour or shading.
  bool hasArcs() const { return ridgeArc.darkening > 0 || ridgeArc.relief > 0; }
  /// True when a ridge (seam or arc) changes colour, shading or geometry.
  bool hasRidge() const { return ridgeDarkening > 0 || ridgeRelief > 0 || hasArcs() || ridgeArc.height > 0; }
};

}  // namespace sprig::textures
