#pragma once
/// Leaf cards: the leaves of a tree's far level of detail as alpha-tested quads
/// (docs/MESHES.md "Levels of detail", "Leaf cards").
///
/// Each leaf (a connected component of a scattered part: ExportPart::scattered) becomes one
/// quad in the leaf's plane, covering the leaf's outline, textured with its own image: the
/// leaf's triangles seen along the plane's normal, rasterized into the quad's cell of one
/// image per part (kLeafCardTexels texels a side, a transparent texel around it), with the
/// leaf's colours (its vertex colours, its image through its uvs, or the base colour) and
/// an alpha of the share of the texel the leaf covers. The part's material cuts the card
/// out where that alpha is below kLeafCardAlphaCutoff (glTF alphaMode MASK).

#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/mesh_io.h"

namespace sprig {

/// Texels per side of one card's cell in the cards' image (the leaf spans all but the
/// outer ring of texels, which stays transparent so that bilinear lookups at the card's
/// edge read no neighbour).
inline constexpr int kLeafCardTexels = 16;
/// At most this many cards a part (their image at most 4096 x 4096 texels, as an atlas:
/// kAtlasMaxSize); leafCards keeps fewer leaves beyond it.
inline constexpr size_t kLeafCardsMax = 65536;
/// The cards' alphaCutoff (a part with its own cut-out keeps its own).
inline constexpr float kLeafCardAlphaCutoff = 0.5f;

/// The connected component (triangles sharing a vertex) of every triangle, numbered in
/// order of their first triangle; count receives how many there are.
std::vector<uint32_t> triangleComponents(const Mesh& mesh, size_t& count);

/// Whether piece j of pieces is among keep evenly spread ones: ⌊(j+1)·keep/pieces⌋ >
/// ⌊j·keep/pieces⌋ (keep ≤ pieces; exactly keep of them are).
inline bool evenlyKept(size_t j, size_t keep, size_t pieces) { return (j + 1) * keep / pieces > j * keep / pieces; }

/// The leaves of part as cards: min(cards, leaves, kLeafCardsMax) of its leaves (at least one), evenly
/// spread over their order (evenlyKept), each a quad of 4 vertices and 2 triangles with the
/// card's normal and uvs into the part's new texture (no vertex colours), the leaves' order
/// kept. A card is the leaf's bounding rectangle in its plane (normal: the leaf's
/// area-weighted normal; long side along the principal axis of its vertices), one texel
/// wider on each side, grown about its centre by one factor so that the cards' leaves cover
/// the area all of part's leaves covered. The material keeps its name, colour and sides,
/// gets the cards' image (LINEAR filters without mipmaps, clamped) and alphaCutoff
/// kLeafCardAlphaCutoff unless it had one. Deterministic; the same bytes at any thread count.
/// A part without triangles is returned unchanged. Cost: one point-in-triangle test per
/// quarter texel and leaf triangle.
ExportPart leafCards(const ExportPart& part, size_t cards);

}  // namespace sprig
