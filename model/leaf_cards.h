#pragma once
/// Leaf cards and crown cards: the leaves of a tree's farthest levels of detail as
/// alpha-tested quads (docs/MESHES.md "Levels of detail", "Leaf cards", "Crown cards: the
/// far impostor").
///
/// Each leaf (a connected component of a scattered part: ExportPart::scattered) becomes one
/// quad in the leaf's plane, covering the leaf's outline, textured with its own image: the
/// leaf's triangles seen along the plane's normal, rasterized into the quad's cell of one
/// image per part (kLeafCardTexels texels a side, a transparent texel around it), with the
/// leaf's colours (its vertex colours, its image through its uvs, or the base colour) and
/// an alpha of the share of the texel the leaf covers. The part's material cuts the card
/// out where that alpha is below kLeafCardAlphaCutoff (glTF alphaMode MASK).
///
/// Crown cards (the last level, the far impostor) put several leaves on one card: the leaves
/// are clustered (k-means of their centroids, crownClusters) and each cluster becomes
/// kCrownCardsPerCluster crossed cards through its centre, each painted as above with all
/// the cluster's leaves seen along its normal, in cells of kCrownCardTexels texels a side.

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

/// Texels per side of one crown card's cell (a cluster of leaves: finer than a leaf's).
inline constexpr int kCrownCardTexels = 64;
/// Cards per crown cluster: three mutually perpendicular ones, each tilted up alike (the
/// faces of a cube standing on a corner; crownCards).
inline constexpr size_t kCrownCardsPerCluster = 3;
/// At most this many crown clusters a part (their cards' image at most 4096 x 4096 texels).
inline constexpr size_t kCrownClustersMax = (4096 / kCrownCardTexels) * (4096 / kCrownCardTexels) / kCrownCardsPerCluster;
/// crownClusters' k-means rounds (a fixed count: the clusters are the same on every machine).
inline constexpr int kCrownClusterRounds = 10;

/// The connected component (triangles sharing a vertex) of every triangle, numbered in
/// order of their first triangle; count receives how many there are.
std::vector<uint32_t> triangleComponents(const Mesh& mesh, size_t& count);

/// The mean of the vertices of each of count components (component: each triangle's, as
/// triangleComponents numbers them); each vertex counted once, vertices of no triangle not.
std::vector<glm::dvec3> componentCentroids(const Mesh& mesh, const std::vector<uint32_t>& component, size_t count);

/// Points (leaves' centroids) in at most clusters groups (at least one; as many as points at
/// most): k-means from clusters evenly spread points (evenlyKept, in the points' order),
/// kCrownClusterRounds rounds of moving each centre to its points' mean, then each point to
/// its nearest centre (the first of equally near ones). Returns each point's cluster,
/// numbered in the order of their first point; count receives how many have points (empty
/// ones are dropped). Deterministic: the same at any thread count. Cost: points · clusters
/// · (kCrownClusterRounds + 1) distances.
std::vector<uint32_t> crownClusters(const std::vector<glm::dvec3>& points, size_t clusters, size_t& count);

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

/// The leaves of part as crown cards: all its leaves (components) in min(clusters,
/// kCrownClustersMax) clusters (crownClusters of their centroids; fewer when some are
/// empty), cluster c as cards kCrownCardsPerCluster·c + 0, 1, 2 (quads of 4 vertices and 2
/// triangles each, in that order), mutually perpendicular, card k's normal
/// √(2/3)·(cos φ_k a + sin φ_k b) + √(1/3)·up with φ_k = 120°·k, a the principal horizontal
/// axis of the cluster's vertices, b = up × a (y is up; the faces of a cube standing on a
/// corner: every card's normal 35.3° above the horizontal, so that light from above and
/// views from the side and from above meet the three alike), its side u = up × (the
/// normal's horizontal direction), v = n × u; each through the mean of the cluster's
/// vertices, the bounding rectangle of them in its plane plus one texel of rim each side;
/// none grown. Each card's cell (kCrownCardTexels a side, in rows as leafCards') holds the
/// cluster's leaves seen along its normal, painted as leafCards paints one leaf (where
/// leaves overlap, the first in the mesh's order). The material as leafCards'. Deterministic; the same bytes at any thread count. A part
/// without triangles is returned unchanged. Cost: a point-in-triangle test per quarter texel
/// of each triangle's box on each of its cluster's cards; leaves · clusters distances a round.
ExportPart crownCards(const ExportPart& part, size_t clusters);

}  // namespace sprig
