#include "model/leaf_cards.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>

#include "core/parallel.h"

namespace sprig {

std::vector<uint32_t> triangleComponents(const Mesh& mesh, size_t& count) {
  std::vector<uint32_t> parent(mesh.positions.size());
  std::iota(parent.begin(), parent.end(), 0u);
  auto find = [&](uint32_t v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
  };
  for (const glm::uvec3& t : mesh.triangles) {
    const uint32_t a = find(t.x), b = find(t.y), c = find(t.z);
    parent[b] = a;
    parent[find(c)] = a;
  }
  std::vector<uint32_t> id(mesh.positions.size(), UINT32_MAX), out(mesh.triangles.size());
  count = 0;
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    uint32_t& c = id[find(mesh.triangles[t].x)];
    if (c == UINT32_MAX) c = uint32_t(count++);
    out[t] = c;
  }
  return out;
}

std::vector<glm::dvec3> componentCentroids(const Mesh& mesh, const std::vector<uint32_t>& component, size_t count) {
  std::vector<uint32_t> of(mesh.positions.size(), UINT32_MAX);
  for (size_t t = 0; t < mesh.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) of[mesh.triangles[t][k]] = component[t];
  std::vector<glm::dvec3> sum(count, glm::dvec3(0.0));
  std::vector<size_t> used(count, 0);
  for (size_t v = 0; v < mesh.positions.size(); ++v)
    if (of[v] != UINT32_MAX) sum[of[v]] += glm::dvec3(mesh.positions[v]), ++used[of[v]];
  for (size_t c = 0; c < count; ++c)
    if (used[c]) sum[c] /= double(used[c]);
  return sum;
}

std::vector<uint32_t> crownClusters(const std::vector<glm::dvec3>& points, size_t clusters, size_t& count) {
  count = 0;
  const size_t n = points.size();
  if (n == 0) return {};
  const size_t k = std::clamp<size_t>(clusters, 1, n);
  std::vector<glm::dvec3> centre;
  for (size_t j = 0; j < n; ++j)
    if (evenlyKept(j, k, n)) centre.push_back(points[j]);
  std::vector<uint32_t> of(n, 0);
  for (int round = 0;; ++round) {
    // Each point to its nearest centre (the first of equally near ones), side by side.
    parallelFor(0, n, [&](size_t j) {
      double best = INFINITY;
      for (size_t c = 0; c < k; ++c) {
        const glm::dvec3 d = points[j] - centre[c];
        const double dd = glm::dot(d, d);
        if (dd < best) best = dd, of[j] = uint32_t(c);
      }
    }, 64);
    if (round == kCrownClusterRounds) break;
    // Each centre to the mean of its points, summed in the points' order (an empty one stays).
    std::vector<glm::dvec3> sum(k, glm::dvec3(0.0));
    std::vector<size_t> size(k, 0);
    for (size_t j = 0; j < n; ++j) sum[of[j]] += points[j], ++size[of[j]];
    for (size_t c = 0; c < k; ++c)
      if (size[c]) centre[c] = sum[c] / double(size[c]);
  }
  // The clusters that have points, numbered in the order of their first point.
  std::vector<uint32_t> id(k, UINT32_MAX);
  for (uint32_t& c : of) {
    if (id[c] == UINT32_MAX) id[c] = uint32_t(count++);
    c = id[c];
  }
  return of;
}

namespace {

double triangleArea(const Mesh& m, const glm::uvec3& t) {
  return 0.5 * glm::length(glm::cross(glm::dvec3(m.positions[t.y] - m.positions[t.x]), glm::dvec3(m.positions[t.z] - m.positions[t.x])));
}

// A card: its plane's frame and its rectangle there (u along the long side for a leaf), and
// the triangles painted on it.
struct Card {
  glm::dvec3 centre{0.0}, u{1, 0, 0}, v{0, 0, 1}, n{0, 1, 0};
  double halfU = 0, halfV = 0;  // half sides, the one-texel rim included
  const std::vector<uint32_t>* tris = nullptr;
};

// The vertices of triangles tris of mesh, each once, and their mean.
std::vector<uint32_t> cornersOf(const Mesh& mesh, const std::vector<uint32_t>& tris, glm::dvec3& mean) {
  std::vector<uint32_t> corners;
  for (uint32_t t : tris) corners.insert(corners.end(), {mesh.triangles[t].x, mesh.triangles[t].y, mesh.triangles[t].z});
  std::sort(corners.begin(), corners.end());
  corners.erase(std::unique(corners.begin(), corners.end()), corners.end());
  mean = glm::dvec3(0.0);
  for (uint32_t v : corners) mean += glm::dvec3(mesh.positions[v]);
  mean /= double(std::max<size_t>(corners.size(), 1));
  return corners;
}

// A frame (e1, e2) of the plane of unit normal n, with e1 x e2 = n.
void planeFrame(const glm::dvec3& n, glm::dvec3& e1, glm::dvec3& e2) {
  const glm::dvec3 a = std::abs(n.y) < 0.9 ? glm::dvec3(0, 1, 0) : glm::dvec3(1, 0, 0);
  e1 = glm::normalize(glm::cross(a, n));
  e2 = glm::cross(n, e1);
}

// The principal axis of the corners about mean in the plane of (e1, e2): a unit vector there.
glm::dvec3 principalAxis(const Mesh& mesh, const std::vector<uint32_t>& corners, const glm::dvec3& mean,
                         const glm::dvec3& e1, const glm::dvec3& e2) {
  double sxx = 0, syy = 0, sxy = 0;
  for (uint32_t v : corners) {
    const glm::dvec3 d = glm::dvec3(mesh.positions[v]) - mean;
    const double x = glm::dot(d, e1), y = glm::dot(d, e2);
    sxx += x * x, syy += y * y, sxy += x * y;
  }
  const double angle = 0.5 * std::atan2(2.0 * sxy, sxx - syy);
  return std::cos(angle) * e1 + std::sin(angle) * e2;
}

// The card of normal n and side u (v = n x u) through mean: the corners' bounding rectangle
// in its plane, at least a hundredth as wide as it is long (a leaf seen edge-on), plus one
// texel of rim each side of a cell of texels a side.
Card fitCard(const Mesh& mesh, const std::vector<uint32_t>& corners, const glm::dvec3& mean, const glm::dvec3& n,
             const glm::dvec3& u, int texels) {
  Card c;
  c.n = n, c.u = u, c.v = glm::cross(n, u);
  double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
  for (uint32_t v : corners) {
    const glm::dvec3 d = glm::dvec3(mesh.positions[v]) - mean;
    const double x = glm::dot(d, c.u), y = glm::dot(d, c.v);
    lo[0] = std::min(lo[0], x), hi[0] = std::max(hi[0], x), lo[1] = std::min(lo[1], y), hi[1] = std::max(hi[1], y);
  }
  const double longest = std::max({hi[0] - lo[0], hi[1] - lo[1], 1e-9});
  double half[2];
  for (int k = 0; k < 2; ++k) {
    const double side = std::max(hi[k] - lo[k], 1e-2 * longest);
    half[k] = 0.5 * side * double(texels) / double(texels - 2);  // one texel of rim each side
  }
  c.centre = mean + c.u * (0.5 * (lo[0] + hi[0])) + c.v * (0.5 * (lo[1] + hi[1]));
  c.halfU = half[0], c.halfV = half[1];
  return c;
}

// The card of the leaf made of triangles tris of mesh: in the plane of the leaf's
// area-weighted normal, its long side along the principal axis of the leaf's vertices.
Card cardOf(const Mesh& mesh, const std::vector<uint32_t>& tris) {
  glm::dvec3 normal(0.0), mean(0.0), n(0, 1, 0), e1, e2;
  const std::vector<uint32_t> corners = cornersOf(mesh, tris, mean);
  for (uint32_t t : tris) {
    const glm::uvec3& tri = mesh.triangles[t];
    normal += glm::cross(glm::dvec3(mesh.positions[tri.y] - mesh.positions[tri.x]), glm::dvec3(mesh.positions[tri.z] - mesh.positions[tri.x]));
  }
  if (glm::length(normal) > 0) n = glm::normalize(normal);
  planeFrame(n, e1, e2);
  Card c = fitCard(mesh, corners, mean, n, principalAxis(mesh, corners, mean, e1, e2), kLeafCardTexels);
  c.tris = &tris;
  return c;
}

// The kCrownCardsPerCluster cards of the cluster of triangles tris of mesh, through the mean
// of its vertices: three mutually perpendicular cards, each tilted up by asin(1/√3) (a
// cube standing on a corner), their normals' horizontal parts 120 degrees apart from a,
// the principal horizontal axis of the cluster's vertices (y is up).
std::array<Card, kCrownCardsPerCluster> clusterCardsOf(const Mesh& mesh, const std::vector<uint32_t>& tris) {
  const glm::dvec3 up(0, 1, 0);
  glm::dvec3 mean(0.0), e1, e2;
  const std::vector<uint32_t> corners = cornersOf(mesh, tris, mean);
  planeFrame(up, e1, e2);
  const glm::dvec3 a = principalAxis(mesh, corners, mean, e1, e2), b = glm::cross(up, a);
  const double rise = std::sqrt(1.0 / 3.0), level = std::sqrt(2.0 / 3.0);
  std::array<Card, kCrownCardsPerCluster> cards;
  for (size_t k = 0; k < kCrownCardsPerCluster; ++k) {
    const double phi = 2.0 * kPi / 3.0 * double(k);
    const glm::dvec3 h = std::cos(phi) * a + std::sin(phi) * b;  // the normal's horizontal direction
    cards[k] = fitCard(mesh, corners, mean, level * h + rise * up, glm::cross(up, h), kCrownCardTexels);
    cards[k].tris = &tris;
  }
  return cards;
}

// The colour and alpha of part's surface at barycentric b of triangle t.
Vec4 surfaceAt(const ExportPart& part, size_t t, const glm::dvec3& b) {
  const Mesh& m = part.mesh;
  const glm::uvec3& tri = m.triangles[t];
  const PartTexture* tex = part.material.texture.get();
  const bool cutOut = part.material.alphaCutoff >= 0.0f;
  if (m.colors.size() == m.positions.size() && !(tex && cutOut))
    return Vec4(Vec3(float(b.x)) * m.colors[tri.x] + Vec3(float(b.y)) * m.colors[tri.y] + Vec3(float(b.z)) * m.colors[tri.z], 1.0f);
  if (!tex || (!tex->isAtlas() && m.uvs.size() != m.positions.size())) return Vec4(part.material.baseColor, 1.0f);
  Vec2 uv(0.0f);
  for (int k = 0; k < 3; ++k)
    uv += float(b[k]) * (tex->isAtlas() ? tex->atlas.values[tex->atlas.index[t * 3 + size_t(k)]] : m.uvs[tri[k]]);
  const Image& im = tex->pixels();
  const auto wrap = [](float s, int n) {
    const int i = int(std::floor(s * float(n)));
    return ((i % n) + n) % n;  // repeats, and clamps the edge texel of a [0, 1] mapping too
  };
  Vec4 c = im.at(wrap(uv.x, im.width), wrap(1.0f - uv.y, im.height));
  if (!cutOut) c.a = 1.0f;
  return c;
}

// Paints the cell of texels a side at (x0, y0) of image with card c's triangles: 2 x 2
// samples a texel; a sample takes the first triangle (in the mesh's order) that covers it,
// seen along the card's normal. A texel's alpha is the sum of its samples' alphas over 4
// (uncovered: 0), its colour their alpha-weighted mean; texels of alpha 0 get the
// triangles' alpha-weighted mean colour (so that bilinear lookups at the outline blend no
// black in).
void paintCell(const ExportPart& part, const Card& c, int texels, Image& image, int x0, int y0) {
  const Mesh& m = part.mesh;
  const int n = texels, s = 2 * n;  // samples a side
  std::vector<Vec4> sample(size_t(s * s), Vec4(-1.0f));  // alpha < 0: not covered
  // Sample (x, y), row 0 at the top (+v), covers card point q.
  const auto point = [&](int x, int y) {
    return glm::dvec2(((x + 0.5) / s * 2 - 1) * c.halfU, (1 - (y + 0.5) / s * 2) * c.halfV);
  };
  for (uint32_t t : *c.tris) {
    glm::dvec2 p[3];
    for (int k = 0; k < 3; ++k) {
      const glm::dvec3 d = glm::dvec3(m.positions[m.triangles[t][k]]) - c.centre;
      p[k] = glm::dvec2(glm::dot(d, c.u), glm::dot(d, c.v));
    }
    const double det = (p[1].x - p[0].x) * (p[2].y - p[0].y) - (p[2].x - p[0].x) * (p[1].y - p[0].y);
    if (!(std::abs(det) > 0)) continue;
    const double lox = std::min({p[0].x, p[1].x, p[2].x}), hix = std::max({p[0].x, p[1].x, p[2].x});
    const double loy = std::min({p[0].y, p[1].y, p[2].y}), hiy = std::max({p[0].y, p[1].y, p[2].y});
    const int xa = std::max(0, int(std::floor((lox / c.halfU + 1) * 0.5 * s - 0.5))),
              xb = std::min(s - 1, int(std::ceil((hix / c.halfU + 1) * 0.5 * s - 0.5)));
    const int ya = std::max(0, int(std::floor((1 - hiy / c.halfV) * 0.5 * s - 0.5))),
              yb = std::min(s - 1, int(std::ceil((1 - loy / c.halfV) * 0.5 * s - 0.5)));
    for (int y = ya; y <= yb; ++y)
      for (int x = xa; x <= xb; ++x) {
        Vec4& out = sample[size_t(y * s + x)];
        if (out.a >= 0.0f) continue;
        const glm::dvec2 q = point(x, y);
        const double b1 = ((q.x - p[0].x) * (p[2].y - p[0].y) - (p[2].x - p[0].x) * (q.y - p[0].y)) / det;
        const double b2 = ((p[1].x - p[0].x) * (q.y - p[0].y) - (q.x - p[0].x) * (p[1].y - p[0].y)) / det;
        if (b1 < 0 || b2 < 0 || b1 + b2 > 1) continue;
        out = surfaceAt(part, t, glm::dvec3(1 - b1 - b2, b1, b2));
      }
  }
  // Colours are weighted by their alpha (a cut-out texel of the leaf's image lends none).
  Vec3 mean(0.0f);
  float weight = 0;
  for (const Vec4& v : sample)
    if (v.a > 0.0f) mean += Vec3(v) * v.a, weight += v.a;
  mean = weight > 0 ? mean / weight : part.material.baseColor;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      Vec3 rgb(0.0f);
      float alpha = 0;
      for (int j = 0; j < 4; ++j) {
        const Vec4& v = sample[size_t((2 * y + j / 2) * s + 2 * x + j % 2)];
        if (v.a > 0.0f) rgb += Vec3(v) * v.a, alpha += v.a;
      }
      image.set(x0 + x, y0 + y, alpha > 0 ? Vec4(rgb / alpha, alpha / 4.0f) : Vec4(mean, 0.0f));
    }
}

// The quad of card c grown by grow, its corners' uvs the cell of texels a side at (x0, y0)
// of a w x h image.
void addQuad(Mesh& out, const Card& c, double grow, int texels, int x0, int y0, int w, int h) {
  const auto base = uint32_t(out.positions.size());
  const double su[4] = {-1, 1, 1, -1}, sv[4] = {-1, -1, 1, 1};
  for (int k = 0; k < 4; ++k) {
    out.positions.push_back(Vec3(c.centre + grow * (su[k] * c.halfU * c.u + sv[k] * c.v * c.halfV)));
    out.normals.push_back(Vec3(c.n));
    const double x = x0 + (su[k] > 0 ? texels : 0), y = y0 + (sv[k] > 0 ? 0 : texels);
    out.uvs.push_back(Vec2(float(x / w), float(1.0 - y / h)));
  }
  // Counter-clockwise seen from +n: u, v, n is right-handed.
  out.triangles.push_back({base, base + 1, base + 2});
  out.triangles.push_back({base, base + 2, base + 3});
}

// part's name, material and cards as quads grown by grow, each card's triangles painted
// into its own cell of texels a side of one new image (cells in rows, ceil(sqrt(cards)) a
// row), the cells painted side by side.
ExportPart cardPart(const ExportPart& part, const std::vector<Card>& cards, int texels, double grow) {
  const auto columns = size_t(std::ceil(std::sqrt(double(cards.size()))));
  const size_t rows = (cards.size() + columns - 1) / columns;
  auto tex = std::make_shared<PartTexture>();
  tex->image = Image(int(columns) * texels, int(rows) * texels, Vec4(0.0f));
  tex->magFilter = tex->minFilter = PartTexture::Filter::Linear;  // a mipmap would mix cells
  const auto x0 = [&](size_t i) { return int(i % columns) * texels; };
  const auto y0 = [&](size_t i) { return int(i / columns) * texels; };
  parallelFor(0, cards.size(), [&](size_t i) { paintCell(part, cards[i], texels, tex->image, x0(i), y0(i)); });
  ExportPart out;
  out.name = part.name;
  out.scattered = part.scattered;
  out.material = part.material;
  out.material.normalTexture.reset();
  if (out.material.alphaCutoff < 0.0f) out.material.alphaCutoff = kLeafCardAlphaCutoff;
  for (size_t i = 0; i < cards.size(); ++i)
    addQuad(out.mesh, cards[i], grow, texels, x0(i), y0(i), tex->image.width, tex->image.height);
  out.material.texture = std::move(tex);
  return out;
}

}  // namespace

ExportPart leafCards(const ExportPart& part, size_t cards) {
  if (part.mesh.triangles.empty()) return part;
  const Mesh& m = part.mesh;
  size_t leaves = 0;
  const std::vector<uint32_t> leaf = triangleComponents(m, leaves);
  const size_t keep = std::clamp<size_t>(std::min(cards, kLeafCardsMax), 1, leaves);
  std::vector<std::vector<uint32_t>> tris(leaves);
  double area = 0, keptArea = 0;
  for (size_t t = 0; t < m.triangles.size(); ++t) {
    tris[leaf[t]].push_back(uint32_t(t));
    const double a = triangleArea(m, m.triangles[t]);
    area += a;
    if (evenlyKept(leaf[t], keep, leaves)) keptArea += a;
  }
  std::vector<uint32_t> kept;
  for (size_t j = 0; j < leaves; ++j)
    if (evenlyKept(j, keep, leaves)) kept.push_back(uint32_t(j));
  const double grow = keptArea > 0 ? std::sqrt(area / keptArea) : 1.0;
  std::vector<Card> card(kept.size());
  parallelFor(0, kept.size(), [&](size_t i) { card[i] = cardOf(m, tris[kept[i]]); });
  return cardPart(part, card, kLeafCardTexels, grow);
}

ExportPart crownCards(const ExportPart& part, size_t clusters) {
  if (part.mesh.triangles.empty()) return part;
  const Mesh& m = part.mesh;
  size_t leaves = 0, count = 0;
  const std::vector<uint32_t> leaf = triangleComponents(m, leaves);
  const std::vector<uint32_t> cluster =
      crownClusters(componentCentroids(m, leaf, leaves), std::min(clusters, kCrownClustersMax), count);
  std::vector<std::vector<uint32_t>> tris(count);
  for (size_t t = 0; t < m.triangles.size(); ++t) tris[cluster[leaf[t]]].push_back(uint32_t(t));
  std::vector<Card> card(count * kCrownCardsPerCluster);
  parallelFor(0, count, [&](size_t c) {
    const std::array<Card, kCrownCardsPerCluster> three = clusterCardsOf(m, tris[c]);
    std::copy(three.begin(), three.end(), card.begin() + ptrdiff_t(c * kCrownCardsPerCluster));
  });
  return cardPart(part, card, kCrownCardTexels, 1.0);
}

}  // namespace sprig
