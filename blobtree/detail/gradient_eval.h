#pragma once
/// Private: the gradient evaluator of the tape (value, analytic gradient and blended
/// attributes at a point).

#include "blobtree/detail/tape.h"

#include <algorithm>
#include <array>

namespace sprig::blobtree::detail {

/// Running blend of attributes: Σ fᵢ·uvᵢ, Σ fᵢ and the heaviest kMaxTextures texture ids.
struct AttrAcc {
  Vec2 uvSum{0.0f};
  float wSum = 0.0f;
  std::array<uint16_t, Attributes::kMaxTextures> ids{};
  std::array<float, Attributes::kMaxTextures> w{};
  int count = 0;

  void addTexture(uint16_t id, float weight) {
    for (int i = 0; i < count; ++i)
      if (ids[size_t(i)] == id) { w[size_t(i)] += weight; return; }
    if (count < Attributes::kMaxTextures) {
      ids[size_t(count)] = id;
      w[size_t(count)] = weight;
      ++count;
      return;
    }
    // Replace the lightest when heavier.
    int k = 0;
    for (int i = 1; i < count; ++i)
      if (w[size_t(i)] < w[size_t(k)]) k = i;
    if (w[size_t(k)] < weight) { ids[size_t(k)] = id; w[size_t(k)] = weight; }
  }
  /// The heaviest primitives so far, each with its own uv (Attributes::layers).
  std::array<Attributes::Layer, Attributes::kMaxLayers> layers{};
  int layerCount = 0;
  float contact = 0.0f;  ///< Attributes::contact
  Vec3 contactGrad{0.0f};  ///< Attributes::contactGradient

  void addLayer(const Attributes::Layer& l) {
    if (layerCount < Attributes::kMaxLayers) {
      layers[size_t(layerCount++)] = l;
      return;
    }
    // Replace the lightest when heavier.
    int k = 0;
    for (int i = 1; i < layerCount; ++i)
      if (layers[size_t(i)].weight < layers[size_t(k)].weight) k = i;
    if (layers[size_t(k)].weight < l.weight) layers[size_t(k)] = l;
  }
  void merge(const AttrAcc& o) {
    uvSum += o.uvSum;
    wSum += o.wSum;
    for (int i = 0; i < o.count; ++i) addTexture(o.ids[size_t(i)], o.w[size_t(i)]);
    for (int i = 0; i < o.layerCount; ++i) addLayer(o.layers[size_t(i)]);
    if (o.contact > contact) {
      contact = o.contact;
      contactGrad = o.contactGrad;
    }
  }
};

/// Value, gradient and attribute sums of a node at a point.
struct SV {
  float v = 0.0f;
  Vec3 g{0.0f};
  AttrAcc acc;
};

/// Value, gradient and attributes of tape node ni at p (children culled by support box).
SV evalS(const Tape& T, uint32_t ni, Vec3 p);

}  // namespace sprig::blobtree::detail
