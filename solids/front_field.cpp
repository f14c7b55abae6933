#include "solids/front_field.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>
#include <stdexcept>

#include "core/parallel.h"

namespace sprig::solids {

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

/// Sethian's first-order upwind update (1999, eq. 8.4): the T solving
/// sum over axes of max(T - a_i, 0)^2 = r^2 with a_i the smallest accepted neighbour along
/// axis i (kInf when none) and r = h / speed. `used` reports how many axes take part.
double solveEikonal(std::array<double, 3> a, double r, int& used) {
  std::sort(a.begin(), a.end());
  double t = a[0] + r;
  used = 1;
  if (t > a[1]) {
    const double s = a[0] + a[1], q = 2 * r * r - (a[0] - a[1]) * (a[0] - a[1]);
    t = 0.5 * (s + std::sqrt(std::max(q, 0.0)));
    used = 2;
    if (t > a[2]) {
      const double s3 = a[0] + a[1] + a[2];
      const double sq = a[0] * a[0] + a[1] * a[1] + a[2] * a[2];
      const double disc = s3 * s3 - 3 * (sq - r * r);
      t = (s3 + std::sqrt(std::max(disc, 0.0))) / 3;
      used = 3;
    }
  }
  return t;
}

/// The lattice nodes next to the zero set of d: zero there, or a neighbour along an axis on
/// the other side. The front starts at them, and painted speeds are asked only there.
std::vector<size_t> zeroSetNodes(const std::vector<float>& d, const std::array<int, 3>& dims) {
  const int64_t stride[3] = {1, dims[0], int64_t(dims[0]) * dims[1]};
  std::vector<size_t> out;
  for (size_t i = 0; i < d.size(); ++i) {
    const int c[3] = {int(i % dims[0]), int((i / dims[0]) % dims[1]), int(i / (size_t(dims[0]) * dims[1]))};
    bool edge = d[i] == 0;
    for (int a = 0; a < 3 && !edge; ++a)
      for (int s = -1; s <= 1 && !edge; s += 2)
        if (c[a] + s >= 0 && c[a] + s < dims[a]) edge = (d[i + s * stride[a]] < 0) != (d[i] < 0);
    if (edge) out.push_back(i);
  }
  return out;
}

/// Field values divided by a constant speed.
class ConstantSpeedField final : public DistanceField {
 public:
  ConstantSpeedField(FieldPtr child, double v) : child_(std::move(child)), v_(v) {
    if (!(v > 0)) throw std::invalid_argument("the velocity must be positive");
  }
  std::vector<float> sample(const std::vector<Vec3>& points, double cell, double band) const override {
    std::vector<float> out = child_->sample(points, cell, band * v_);
    for (float& x : out) x = float(x / v_);
    return out;
  }
  std::optional<DBox3> bounds() const override { return child_->bounds(); }
  double reach() const override { return v_ * child_->reach(); }

 private:
  FieldPtr child_;
  double v_;
};

/// Arrival times of a front with variable speed, on a lattice around each batch.
class FrontField final : public DistanceField {
 public:
  FrontField(FieldPtr child, SpeedFn speed, double maxSpeed, bool painted)
      : child_(std::move(child)), speed_(std::move(speed)), max_(std::max(maxSpeed, double(kMinSpeed))), painted_(painted) {}

  std::vector<float> sample(const std::vector<Vec3>& points, double h, double band) const override {
    std::vector<float> out(points.size());
    if (points.empty()) return out;
    DBox3 box;
    for (const Vec3& p : points) box.extend(DVec3(p));
    // The lattice: two cells beyond the points on every side, so every point has its 8 nodes.
    const DVec3 origin = box.lo - 2 * h;
    std::array<int, 3> dims{};
    for (int a = 0; a < 3; ++a) dims[a] = int(std::ceil((box.hi[a] - box.lo[a]) / h)) + 5;
    const size_t n = size_t(dims[0]) * dims[1] * dims[2];
    std::vector<Vec3> nodes(n);
    parallelFor(0, size_t(dims[2]), [&](size_t k) {
      for (int j = 0; j < dims[1]; ++j)
        for (int i = 0; i < dims[0]; ++i)
          nodes[i + size_t(dims[0]) * (j + size_t(dims[1]) * k)] = Vec3(origin + h * DVec3(i, j, int(k)));
    });
    const double limit = band + 2 * h;
    const std::vector<float> d = child_->sample(nodes, h, limit * max_ + 3 * h);
    std::vector<float> speed(n, 1.0f);
    if (painted_) {
      // Only the nodes next to the zero set need the painted value; the march extends it.
      const std::vector<size_t> front = zeroSetNodes(d, dims);
      std::vector<Vec3> at(front.size());
      for (size_t k = 0; k < front.size(); ++k) at[k] = nodes[front[k]];
      std::vector<float> v(front.size(), 1.0f);
      speed_(at, v);
      for (size_t k = 0; k < front.size(); ++k) speed[front[k]] = v[k];
    } else {
      speed_(nodes, speed);
    }
    const std::vector<float> t = marchFront(d, speed, dims, h, limit, painted_);
    parallelFor(0, points.size(), [&](size_t p) {
      const DVec3 f = (DVec3(points[p]) - origin) / h;
      int c[3];
      double w[3];
      for (int a = 0; a < 3; ++a) {
        c[a] = std::clamp(int(std::floor(f[a])), 0, dims[a] - 2);
        w[a] = std::clamp(f[a] - c[a], 0.0, 1.0);
      }
      double v = 0;
      for (int corner = 0; corner < 8; ++corner) {
        const int di = corner & 1, dj = (corner >> 1) & 1, dk = (corner >> 2) & 1;
        const double wt = (di ? w[0] : 1 - w[0]) * (dj ? w[1] : 1 - w[1]) * (dk ? w[2] : 1 - w[2]);
        v += wt * t[(c[0] + di) + size_t(dims[0]) * ((c[1] + dj) + size_t(dims[1]) * (c[2] + dk))];
      }
      out[p] = float(v);
    }, 4096);
    return out;
  }
  std::optional<DBox3> bounds() const override { return child_->bounds(); }
  double reach() const override { return max_; }

 private:
  FieldPtr child_;
  SpeedFn speed_;
  double max_;
  bool painted_;
};

}  // namespace

namespace {

/// One fast march. extend = false: arrival times at the given speeds. extend = true: unit
/// speed (distance), and the speeds of the nodes next to the zero set are carried to every
/// node reached, along the distance's characteristics (the surface normals).
std::vector<float> march(const std::vector<float>& d, std::vector<float>& speed, const std::array<int, 3>& dims, double h,
                         double limit, bool extend) {
  const size_t n = d.size();
  const int64_t stride[3] = {1, dims[0], int64_t(dims[0]) * dims[1]};
  std::vector<float> t(n, kInf);
  enum : uint8_t { Far, Trial, Known };
  std::vector<uint8_t> state(n, Far);
  auto coord = [&](size_t idx, int a) {
    return a == 0 ? int(idx % dims[0]) : a == 1 ? int((idx / dims[0]) % dims[1]) : int(idx / (size_t(dims[0]) * dims[1]));
  };
  // Nodes next to the zero set: the distance to the crossings on their edges, combined over
  // the axes as 1/D^2 = sum 1/D_a^2 (the usual first-order initialization).
  for (size_t i : zeroSetNodes(d, dims)) {
    const bool in = d[i] < 0;
    double inv = 0;
    bool front = d[i] == 0;
    for (int a = 0; a < 3 && !front; ++a) {
      const int c = coord(i, a);
      double best = kInf;
      for (int s = -1; s <= 1; s += 2) {
        if (c + s < 0 || c + s >= dims[a]) continue;
        const float dn = d[i + s * stride[a]];
        if ((dn < 0) == in) continue;
        best = std::min(best, h * std::abs(d[i]) / (std::abs(d[i]) + std::abs(dn)));
      }
      if (best == 0) front = true;
      else if (best < kInf) inv += 1 / (best * best);
    }
    const double dist = front ? 0.0 : 1 / std::sqrt(inv);
    t[i] = float(extend ? dist : dist / speed[i]);
    state[i] = Known;
  }

  using Entry = std::pair<float, size_t>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> heap;
  auto update = [&](size_t i) {
    std::array<double, 3> a{};
    std::array<double, 3> sp{};
    for (int ax = 0; ax < 3; ++ax) {
      const int c = coord(i, ax);
      a[ax] = kInf;
      for (int s = -1; s <= 1; s += 2) {
        if (c + s < 0 || c + s >= dims[ax]) continue;
        const size_t j = i + s * stride[ax];
        if (state[j] == Known && t[j] < a[ax]) {
          a[ax] = t[j];
          sp[ax] = speed[j];
        }
      }
    }
    int used = 0;
    const double ti = solveEikonal(a, extend ? h : h / speed[i], used);
    double v = speed[i];
    if (extend) {
      // Extension: the speed is constant along the characteristics, ∇v·∇T = 0, discretely
      // the average of the upwind neighbours' speeds weighted by (T - T_a) (Adalsteinsson
      // and Sethian 1999).
      double num = 0, den = 0;
      for (int ax = 0; ax < 3; ++ax)
        if (a[ax] < ti) num += (ti - a[ax]) * sp[ax], den += ti - a[ax];
      if (den > 0) v = std::max(num / den, double(kMinSpeed));
    }
    if (ti < t[i]) {
      t[i] = float(ti);
      speed[i] = float(v);
      state[i] = Trial;
      heap.emplace(t[i], i);
    }
  };
  auto neighbours = [&](size_t i, auto&& visit) {
    for (int ax = 0; ax < 3; ++ax) {
      const int c = coord(i, ax);
      if (c > 0) visit(i - stride[ax]);
      if (c + 1 < dims[ax]) visit(i + stride[ax]);
    }
  };
  for (size_t i = 0; i < n; ++i)
    if (state[i] == Known) neighbours(i, [&](size_t j) { if (state[j] != Known) update(j); });
  while (!heap.empty()) {
    const auto [ti, i] = heap.top();
    heap.pop();
    if (state[i] == Known || ti != t[i]) continue;
    if (ti > limit) break;
    state[i] = Known;
    neighbours(i, [&](size_t j) { if (state[j] != Known) update(j); });
  }
  for (size_t i = 0; i < n; ++i) {
    const float mag = state[i] == Known ? std::min(t[i], float(limit)) : float(limit);
    t[i] = d[i] < 0 ? -mag : mag;
  }
  return t;
}

}  // namespace

std::vector<float> marchFront(const std::vector<float>& d, std::vector<float>& speed, const std::array<int, 3>& dims,
                              double h, double limit, bool painted) {
  for (float& s : speed) s = std::isfinite(s) ? std::max(s, kMinSpeed) : 1.0f;
  if (painted) {
    // The painted speeds first travel along the normals (a unit-speed march as far as the
    // fastest front gets), then the front runs at them.
    march(d, speed, dims, h, limit * std::max(1.0f, *std::max_element(speed.begin(), speed.end())), true);
  }
  return march(d, speed, dims, h, limit, false);
}

SpeedFn uniformSpeed(float v) {
  return [v](const std::vector<Vec3>&, std::vector<float>& out) { std::fill(out.begin(), out.end(), v); };
}

FieldPtr constantSpeedField(FieldPtr child, double speed) { return std::make_shared<ConstantSpeedField>(std::move(child), speed); }

FieldPtr frontField(FieldPtr child, SpeedFn speed, double maxSpeed, bool painted) {
  return std::make_shared<FrontField>(std::move(child), std::move(speed), maxSpeed, painted);
}

}  // namespace sprig::solids
