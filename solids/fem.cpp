#include "solids/fem.h"

#include <Eigen/Eigenvalues>
#include <Eigen/IterativeLinearSolvers>
#include <Eigen/Sparse>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>

#include "core/parallel.h"
#include "core/progress.h"

namespace sprig::solids::detail {
class ParallelProduct;
}

namespace Eigen::internal {
/// ParallelProduct stands in for the sparse matrix in ConjugateGradient (Eigen's
/// "matrix-free solver" interface), so it shares a sparse matrix's traits.
template <>
struct traits<sprig::solids::detail::ParallelProduct> : public traits<SparseMatrix<double>> {};
}  // namespace Eigen::internal

namespace sprig::solids::detail {

/// The symmetric stiffness matrix K seen by conjugate gradients: K·x computed in parallel,
/// one output entry per column (K = Kᵀ, so entry j is column j · x), each summed in the
/// column's order by one thread, so the product is the same bytes at any thread count.
/// Each product advances the progress bar (and notices a cancellation request).
class ParallelProduct : public Eigen::EigenBase<ParallelProduct> {
 public:
  using Scalar = double;
  using RealScalar = double;
  using StorageIndex = int;
  enum { ColsAtCompileTime = Eigen::Dynamic, MaxColsAtCompileTime = Eigen::Dynamic, IsRowMajor = false };

  ParallelProduct(const Eigen::SparseMatrix<double>& k, Progress& progress) : k_(k), progress_(progress) {}
  Eigen::Index rows() const { return k_.rows(); }
  Eigen::Index cols() const { return k_.cols(); }

  template <class Rhs>
  Eigen::Product<ParallelProduct, Rhs, Eigen::AliasFreeProduct> operator*(const Eigen::MatrixBase<Rhs>& x) const {
    return Eigen::Product<ParallelProduct, Rhs, Eigen::AliasFreeProduct>(*this, x.derived());
  }

  /// dst += alpha·K·x.
  template <class Dest, class Rhs>
  void addProduct(Dest& dst, const Rhs& x, double alpha) const {
    const int* outer = k_.outerIndexPtr();
    const int* inner = k_.innerIndexPtr();
    const double* value = k_.valuePtr();
    parallelForRange(0, size_t(k_.cols()), [&](size_t lo, size_t hi) {
      for (size_t j = lo; j < hi; ++j) {
        double sum = 0;
        for (int e = outer[j]; e < outer[j + 1]; ++e) sum += value[e] * x.coeff(inner[e]);
        dst.coeffRef(Eigen::Index(j)) += alpha * sum;
      }
    }, 2048);
    progress_.advance();
  }

  /// The inverse diagonal (for the Jacobi preconditioner).
  Eigen::VectorXd inverseDiagonal() const {
    Eigen::VectorXd d = k_.diagonal();
    for (Eigen::Index i = 0; i < d.size(); ++i) d[i] = d[i] != 0 ? 1 / d[i] : 1;
    return d;
  }

 private:
  const Eigen::SparseMatrix<double>& k_;
  Progress& progress_;
};

/// Jacobi preconditioning for ParallelProduct (Eigen's DiagonalPreconditioner needs the
/// sparse matrix's iterators): z = D⁻¹·r.
class JacobiPreconditioner {
 public:
  JacobiPreconditioner() = default;
  JacobiPreconditioner& analyzePattern(const ParallelProduct&) { return *this; }
  JacobiPreconditioner& factorize(const ParallelProduct& k) {
    inv_ = k.inverseDiagonal();
    return *this;
  }
  JacobiPreconditioner& compute(const ParallelProduct& k) { return factorize(k); }
  template <class Rhs>
  Eigen::VectorXd solve(const Eigen::MatrixBase<Rhs>& r) const { return inv_.cwiseProduct(r); }
  Eigen::ComputationInfo info() const { return Eigen::Success; }

 private:
  Eigen::VectorXd inv_;
};

}  // namespace sprig::solids::detail

namespace Eigen::internal {
template <class Rhs>
struct generic_product_impl<sprig::solids::detail::ParallelProduct, Rhs, SparseShape, DenseShape, GemvProduct>
    : generic_product_impl_base<sprig::solids::detail::ParallelProduct, Rhs,
                                generic_product_impl<sprig::solids::detail::ParallelProduct, Rhs>> {
  template <class Dest>
  static void scaleAndAddTo(Dest& dst, const sprig::solids::detail::ParallelProduct& lhs, const Rhs& rhs, const double& alpha) {
    lhs.addProduct(dst, rhs, alpha);
  }
};
}  // namespace Eigen::internal

namespace sprig::solids {

namespace {

using SpMat = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;
using Clock = std::chrono::steady_clock;

double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

bool finite(const DVec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

/// Shape-function gradients, volume and Lamé constants of one tetrahedron.
struct Element {
  std::array<DVec3, 4> g;  ///< ∇N_a, 1/m
  double volume = 0;       ///< m³
  double lambda = 0, mu = 0;  ///< Pa
};

/// g_a for a tetrahedron: rows of J⁻¹ with J = [x1−x0, x2−x0, x3−x0] (columns), g_0 = −Σ.
Element element(const TetMesh& m, size_t t, const std::vector<Material>& materials, double scale = 1.0) {
  const auto& q = m.tets[t];
  const DVec3 x0 = m.positions[q[0]];
  const DMat3 J(m.positions[q[1]] - x0, m.positions[q[2]] - x0, m.positions[q[3]] - x0);  // columns
  Element e;
  const double det = glm::determinant(J);
  e.volume = det / 6.0;
  if (!(e.volume > 0) || !std::isfinite(det)) return e;
  const DMat3 inv = glm::inverse(J);  // inv[c][r]: row r of J⁻¹ is ∇N_{r+1}
  for (int r = 0; r < 3; ++r) e.g[size_t(r + 1)] = DVec3(inv[0][r], inv[1][r], inv[2][r]);
  e.g[0] = -(e.g[1] + e.g[2] + e.g[3]);
  const Material& mat = materials[m.materials[t]];
  const double E = mat.youngsModulus * scale, nu = mat.poissonRatio;
  e.lambda = E * nu / ((1 + nu) * (1 - 2 * nu));
  e.mu = E / (2 * (1 + nu));
  return e;
}

/// K_ab = V·(λ·g_a g_bᵀ + μ·g_b g_aᵀ + μ·(g_a·g_b)·I), entry [i][j] (row i of a, column j of b).
void addBlock(const Element& e, int a, int b, double (&k)[3][3]) {
  const DVec3& ga = e.g[size_t(a)];
  const DVec3& gb = e.g[size_t(b)];
  const double dot = glm::dot(ga, gb);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      k[i][j] += e.volume * (e.lambda * ga[i] * gb[j] + e.mu * ga[j] * gb[i] + (i == j ? e.mu * dot : 0.0));
}

std::vector<Element> elements(const TetMesh& mesh, const std::vector<Material>& materials,
                              const std::vector<double>& scale) {
  for (size_t t = 0; t < mesh.tets.size(); ++t) {
    const uint16_t id = mesh.materials[t];
    if (id >= materials.size())
      throw std::invalid_argument("fem: tetrahedron " + std::to_string(t) + " has material id " + std::to_string(id) +
                                  ", but there are " + std::to_string(materials.size()) + " materials");
    for (uint32_t v : mesh.tets[t])
      if (v >= mesh.positions.size())
        throw std::invalid_argument("fem: tetrahedron " + std::to_string(t) + " uses vertex " + std::to_string(v) +
                                    " of " + std::to_string(mesh.positions.size()));
  }
  for (const Material& mat : materials)
    if (!(mat.youngsModulus > 0) || !std::isfinite(mat.youngsModulus) || !(mat.poissonRatio > -1) ||
        !(mat.poissonRatio < 0.5))
      throw std::invalid_argument("fem: material '" + mat.name + "' needs Young's modulus > 0 and Poisson ratio in (-1, 0.5)");
  std::vector<Element> out(mesh.tets.size());
  parallelFor(0, out.size(), [&](size_t t) { out[t] = element(mesh, t, materials, scale.empty() ? 1.0 : scale[t]); }, 1024);
  for (size_t t = 0; t < out.size(); ++t)
    if (!(out[t].volume > 0))
      throw std::invalid_argument("fem: tetrahedron " + std::to_string(t) + " has non-positive or undefined volume " +
                                  std::to_string(out[t].volume));
  return out;
}

/// Tetrahedra around each vertex, in ascending order (CSR).
struct VertexTets {
  std::vector<uint32_t> offset, tets;
  size_t count(size_t v) const { return offset[v + 1] - offset[v]; }
};

VertexTets vertexTets(const TetMesh& mesh) {
  VertexTets vt;
  vt.offset.assign(mesh.positions.size() + 1, 0);
  for (const auto& q : mesh.tets)
    for (uint32_t v : q) ++vt.offset[v + 1];
  std::partial_sum(vt.offset.begin(), vt.offset.end(), vt.offset.begin());
  vt.tets.resize(vt.offset.back());
  std::vector<uint32_t> fill(vt.offset.begin(), vt.offset.end() - 1);
  for (size_t t = 0; t < mesh.tets.size(); ++t)
    for (uint32_t v : mesh.tets[t]) vt.tets[fill[v]++] = uint32_t(t);
  return vt;
}

void checkSize(size_t got, size_t want, const char* what) {
  if (got != 0 && got != want)
    throw std::invalid_argument(std::string("fem: ") + what + " has " + std::to_string(got) +
                                " entries; the mesh has " + std::to_string(want) + " vertices");
}

DVec3 principal(const std::array<double, 6>& s) {
  Eigen::Matrix3d m;
  m << s[0], s[5], s[4], s[5], s[1], s[3], s[4], s[3], s[2];
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es;
  es.computeDirect(m, Eigen::EigenvaluesOnly);
  const Eigen::Vector3d ev = es.eigenvalues();  // ascending
  return DVec3(ev[0], ev[1], ev[2]);
}

/// Conjugate gradients on K (a SpMat, or detail::ParallelProduct wrapping one) with
/// preconditioner Pre; fills x (the initial guess on entry) and the solve's statistics.
template <class Pre, class Mat>
void runCg(const Mat& K, const Eigen::VectorXd& b, Eigen::VectorXd& x, const FemOptions& options, FemStats& st) {
  Eigen::ConjugateGradient<Mat, Eigen::Lower | Eigen::Upper, Pre> cg;
  cg.setTolerance(options.tolerance);
  if (options.maxIterations > 0) cg.setMaxIterations(options.maxIterations);
  auto t0 = Clock::now();
  cg.compute(K);
  st.preconditionerSeconds = since(t0);
  if (cg.info() != Eigen::Success) throw std::runtime_error("fem: the preconditioner could not be built (the matrix is not positive definite)");
  t0 = Clock::now();
  x = cg.solveWithGuess(b, x);
  st.solveSeconds = since(t0);
  st.iterations = int(cg.iterations());
  const double bn = b.norm();
  Eigen::VectorXd r = b;
  r.noalias() -= K * x;
  st.residual = bn > 0 ? r.norm() / bn : 0.0;
  st.converged = cg.info() == Eigen::Success;
}

}  // namespace

std::pair<std::vector<uint32_t>, uint32_t> faceComponents(const TetMesh& mesh) {
  // Faces as (sorted vertex triple, tetrahedron), sorted: equal triples are adjacent.
  struct Face {
    std::array<uint32_t, 3> k;
    uint32_t t;
  };
  std::vector<Face> faces;
  faces.reserve(mesh.tets.size() * 4);
  for (size_t t = 0; t < mesh.tets.size(); ++t)
    for (const auto& f : kTetFaces) {
      const auto& q = mesh.tets[t];
      std::array<uint32_t, 3> k = {q[size_t(f[0])], q[size_t(f[1])], q[size_t(f[2])]};
      std::sort(k.begin(), k.end());
      faces.push_back({k, uint32_t(t)});
    }
  std::sort(faces.begin(), faces.end(), [](const Face& a, const Face& b) { return a.k != b.k ? a.k < b.k : a.t < b.t; });
  std::vector<uint32_t> parent(mesh.tets.size());
  std::iota(parent.begin(), parent.end(), 0u);
  auto find = [&](uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  for (size_t i = 1; i < faces.size(); ++i)
    if (faces[i].k == faces[i - 1].k) {
      const uint32_t a = find(faces[i].t), b = find(faces[i - 1].t);
      if (a != b) parent[std::max(a, b)] = std::min(a, b);
    }
  std::vector<uint32_t> label(mesh.tets.size());
  std::vector<uint32_t> id(mesh.tets.size(), UINT32_MAX);
  uint32_t count = 0;
  for (size_t t = 0; t < mesh.tets.size(); ++t) {
    const uint32_t r = find(uint32_t(t));
    if (id[r] == UINT32_MAX) id[r] = count++;
    label[t] = id[r];
  }
  return {label, count};
}

std::vector<bool> componentsHeld(const TetMesh& mesh, const std::vector<uint32_t>& component, uint32_t count,
                                 const std::vector<uint8_t>& fixed) {
  // The rigid motions of a component are u(x) = τ + ω × x. A fixed component i at vertex p
  // demands e_i·(τ + ω × p) = 0, the row r = (e_i, p × e_i) in the unknowns (τ, ω); the
  // component is held when these rows span all six (the Gram matrix Σ r rᵀ is regular).
  // p is taken from the component's box centre and scaled by its size, for conditioning.
  std::vector<std::pair<uint32_t, uint32_t>> pairs;  // (component, vertex)
  pairs.reserve(mesh.tets.size() * 4);
  for (size_t t = 0; t < mesh.tets.size(); ++t)
    for (uint32_t v : mesh.tets[t]) pairs.push_back({component[t], v});
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  std::vector<DBox3> box(count);
  for (const auto& [c, v] : pairs) box[c].extend(mesh.positions[v]);
  std::vector<Eigen::Matrix<double, 6, 6>> gram(count, Eigen::Matrix<double, 6, 6>::Zero());
  for (const auto& [c, v] : pairs) {
    const uint8_t bits = v < fixed.size() ? fixed[v] : 0;
    if (!bits) continue;
    const DVec3 size = box[c].hi - box[c].lo;
    const double s = std::max({size.x, size.y, size.z, 1e-300});
    const DVec3 p = (mesh.positions[v] - 0.5 * (box[c].lo + box[c].hi)) / s;
    for (int i = 0; i < 3; ++i) {
      if (!(bits & (1 << i))) continue;
      DVec3 e(0.0);
      e[i] = 1;
      const DVec3 w = glm::cross(p, e);
      Eigen::Matrix<double, 6, 1> r;
      r << e.x, e.y, e.z, w.x, w.y, w.z;
      gram[c] += r * r.transpose();
    }
  }
  std::vector<bool> held(count);
  for (uint32_t c = 0; c < count; ++c) {
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> es(gram[c], Eigen::EigenvaluesOnly);
    const auto ev = es.eigenvalues();
    held[c] = ev[5] > 0 && ev[0] > 1e-12 * ev[5];
  }
  return held;
}

FemResult solveElastic(const TetMesh& mesh, const std::vector<Material>& materials, const FemProblem& problem,
                       const FemOptions& options) {
  const size_t nv = mesh.positions.size();
  checkSize(problem.forces.size(), nv, "forces");
  checkSize(problem.fixed.size(), nv, "fixed");
  checkSize(problem.prescribed.size(), nv, "prescribed");
  checkSize(problem.initialGuess.size(), nv, "initialGuess");
  if (!problem.stiffnessScale.empty() && problem.stiffnessScale.size() != mesh.tets.size())
    throw std::invalid_argument("fem: 'stiffnessScale' has " + std::to_string(problem.stiffnessScale.size()) +
                                " entries; the mesh has " + std::to_string(mesh.tets.size()) + " tetrahedra");
  for (size_t t = 0; t < problem.stiffnessScale.size(); ++t)
    if (!(problem.stiffnessScale[t] > 0) || !std::isfinite(problem.stiffnessScale[t]))
      throw std::invalid_argument("fem: the stiffness scale of tetrahedron " + std::to_string(t) + " is not a finite positive number");
  if (mesh.materials.size() != mesh.tets.size())
    throw std::invalid_argument("fem: the mesh has " + std::to_string(mesh.tets.size()) + " tetrahedra but " +
                                std::to_string(mesh.materials.size()) + " material ids");
  for (size_t v = 0; v < problem.forces.size(); ++v)
    if (!finite(problem.forces[v]))
      throw std::invalid_argument("fem: the force at vertex " + std::to_string(v) + " is not finite");
  for (size_t v = 0; v < problem.prescribed.size(); ++v)
    if (!finite(problem.prescribed[v]))
      throw std::invalid_argument("fem: the prescribed displacement of vertex " + std::to_string(v) + " is not finite");
  for (size_t v = 0; v < problem.initialGuess.size(); ++v)
    if (!finite(problem.initialGuess[v]))
      throw std::invalid_argument("fem: the initial guess at vertex " + std::to_string(v) + " is not finite");
  if (!finite(problem.acceleration)) throw std::invalid_argument("fem: the acceleration is not finite");
  if (!(options.tolerance > 0)) throw std::invalid_argument("fem: the tolerance must be positive");

  FemResult res;
  FemStats& st = res.stats;
  const auto t0 = Clock::now();
  const std::vector<Element> el = elements(mesh, materials, problem.stiffnessScale);
  const VertexTets vt = vertexTets(mesh);

  // Step 1: which components are fixed (unused vertices: all), and whether that holds every
  // face-connected part of the mesh.
  std::vector<uint8_t> fixed(nv, 0);
  for (size_t v = 0; v < nv; ++v) fixed[v] = vt.count(v) == 0 ? 7 : (problem.fixed.empty() ? 0 : problem.fixed[v] & 7);
  {
    const auto [component, count] = faceComponents(mesh);
    const std::vector<bool> held = componentsHeld(mesh, component, count, fixed);
    for (uint32_t c = 0; c < count; ++c)
      if (!held[c]) {
        const size_t first = size_t(std::find(component.begin(), component.end(), c) - component.begin());
        throw std::invalid_argument(
            "fem: the system is singular: the part of the mesh holding tetrahedron " + std::to_string(first) +
            " can move rigidly (fix at least three vertices not on one line in each connected part)");
      }
  }

  // Step 2: number the free degrees of freedom vertex by vertex.
  std::vector<int> dof(3 * nv, -1);
  int nFree = 0;
  for (size_t v = 0; v < nv; ++v)
    for (int i = 0; i < 3; ++i)
      if (!(fixed[v] & (1 << i))) dof[3 * v + size_t(i)] = nFree++;
  st.dofs = 3 * nv;
  st.freeDofs = size_t(nFree);

  // Step 3: each vertex's neighbours (itself included), sorted; the free matrix's column
  // (a, i) holds rows (b, j) for free j of every neighbour b, in ascending order.
  std::vector<std::vector<uint32_t>> nbrs(nv);
  parallelFor(0, nv, [&](size_t a) {
    auto& n = nbrs[a];
    for (uint32_t k = vt.offset[a]; k < vt.offset[a + 1]; ++k)
      for (uint32_t b : mesh.tets[vt.tets[k]]) n.push_back(b);
    std::sort(n.begin(), n.end());
    n.erase(std::unique(n.begin(), n.end()), n.end());
  }, 256);
  std::vector<int> freeRows(nv, 0);  // free dofs among a vertex's neighbours
  parallelFor(0, nv, [&](size_t a) {
    int c = 0;
    for (uint32_t b : nbrs[a]) c += 3 - __builtin_popcount(fixed[b]);
    freeRows[a] = c;
  }, 1024);
  SpMat K(nFree, nFree);
  std::vector<int> outer(size_t(nFree) + 1, 0);
  for (size_t a = 0; a < nv; ++a)
    for (int i = 0; i < 3; ++i)
      if (int d = dof[3 * a + size_t(i)]; d >= 0) outer[size_t(d) + 1] = freeRows[a];
  std::partial_sum(outer.begin(), outer.end(), outer.begin());
  K.resizeNonZeros(outer.back());
  std::copy(outer.begin(), outer.end(), K.outerIndexPtr());
  st.nonZeros = size_t(outer.back());

  // Step 4: the blocks K_ab summed over a's tetrahedra in index order; fixed columns move
  // to the right-hand side with their prescribed values; loads gathered the same way.
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(nFree);
  int* inner = K.innerIndexPtr();
  double* value = K.valuePtr();
  parallelFor(0, nv, [&](size_t a) {
    const auto& n = nbrs[a];
    std::vector<std::array<double, 9>> blocks(n.size(), std::array<double, 9>{});
    DVec3 load = problem.forces.empty() ? DVec3(0.0) : problem.forces[a];
    for (uint32_t k = vt.offset[a]; k < vt.offset[a + 1]; ++k) {
      const uint32_t t = vt.tets[k];
      const auto& q = mesh.tets[t];
      const int la = int(std::find(q.begin(), q.end(), uint32_t(a)) - q.begin());
      for (int lb = 0; lb < 4; ++lb) {
        const size_t slot = size_t(std::lower_bound(n.begin(), n.end(), q[size_t(lb)]) - n.begin());
        double k3[3][3] = {};
        addBlock(el[t], la, lb, k3);
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) blocks[slot][size_t(3 * i + j)] += k3[i][j];
      }
      load += (materials[mesh.materials[t]].density * el[t].volume * 0.25) * problem.acceleration;
    }
    for (int i = 0; i < 3; ++i) {
      const int col = dof[3 * a + size_t(i)];
      if (col < 0) continue;
      int at = outer[size_t(col)];
      double r = load[i];
      for (size_t s = 0; s < n.size(); ++s) {
        const uint32_t b = n[s];
        for (int j = 0; j < 3; ++j) {
          const double kij = blocks[s][size_t(3 * i + j)];
          if (const int row = dof[3 * b + size_t(j)]; row >= 0) {
            inner[at] = row;
            value[at] = kij;
            ++at;
          } else if (!problem.prescribed.empty()) {
            r -= kij * problem.prescribed[b][j];
          }
        }
      }
      rhs[col] = r;
    }
  }, 64);
  st.assemblySeconds = since(t0);

  // Step 5: conjugate gradients on the free system.
  Eigen::VectorXd x = Eigen::VectorXd::Zero(nFree);
  if (!problem.initialGuess.empty())
    for (size_t v = 0; v < nv; ++v)
      for (int i = 0; i < 3; ++i)
        if (int d = dof[3 * v + size_t(i)]; d >= 0) x[d] = problem.initialGuess[v][i];
  if (nFree > 0) {
    Progress progress("FEM solve (CG iterations)", 0);
    if (options.preconditioner == Preconditioner::Jacobi) {
      // The products run in parallel; CG's dot products and updates stay sequential.
      const detail::ParallelProduct product(K, progress);
      runCg<detail::JacobiPreconditioner>(product, rhs, x, options, st);
    } else {
      runCg<Eigen::IncompleteCholesky<double>>(K, rhs, x, options, st);
    }
    progress.finish();
    if (!x.allFinite()) throw std::runtime_error("fem: the solve produced non-finite displacements");
    if (!st.converged && options.requireConvergence)
      throw std::runtime_error("fem: conjugate gradients did not converge in " + std::to_string(st.iterations) +
                               " iterations (relative residual " + std::to_string(st.residual) + ")");
  }

  // Step 6: displacements (fixed components take their prescribed values exactly), then
  // each tetrahedron's strain ε = sym(Σ_a u_a ⊗ g_a), stress σ = λ·tr(ε)·I + 2μ·ε.
  res.displacement.assign(nv, DVec3(0.0));
  for (size_t v = 0; v < nv; ++v)
    for (int i = 0; i < 3; ++i) {
      const int d = dof[3 * v + size_t(i)];
      res.displacement[v][i] = d >= 0 ? x[d] : (problem.prescribed.empty() || vt.count(v) == 0 ? 0.0 : problem.prescribed[v][i]);
    }
  const auto t1 = Clock::now();
  res.tets.resize(mesh.tets.size());
  parallelFor(0, mesh.tets.size(), [&](size_t t) {
    const auto& q = mesh.tets[t];
    const Element& e = el[t];
    DMat3 grad(0.0);  // grad[j][i] = ∂u_i/∂x_j
    for (int a = 0; a < 4; ++a) grad += glm::outerProduct(res.displacement[q[size_t(a)]], e.g[size_t(a)]);
    auto eps = [&](int i, int j) { return 0.5 * (grad[j][i] + grad[i][j]); };
    TetStress& s = res.tets[t];
    s.strain = {eps(0, 0), eps(1, 1), eps(2, 2), eps(1, 2), eps(0, 2), eps(0, 1)};
    const double tr = s.strain[0] + s.strain[1] + s.strain[2];
    for (int k = 0; k < 3; ++k) s.stress[size_t(k)] = e.lambda * tr + 2 * e.mu * s.strain[size_t(k)];
    for (int k = 3; k < 6; ++k) s.stress[size_t(k)] = 2 * e.mu * s.strain[size_t(k)];
    const auto& p = s.stress;
    s.vonMises = std::sqrt(0.5 * ((p[0] - p[1]) * (p[0] - p[1]) + (p[1] - p[2]) * (p[1] - p[2]) + (p[2] - p[0]) * (p[2] - p[0])) +
                           3 * (p[3] * p[3] + p[4] * p[4] + p[5] * p[5]));
    s.maxPrincipal = principal(p).z;
  }, 1024);
  st.stressSeconds = since(t1);
  return res;
}

std::pair<size_t, double> assembleStiffnessSequential(const TetMesh& mesh, const std::vector<Material>& materials) {
  std::vector<Eigen::Triplet<double>> trip;
  trip.reserve(mesh.tets.size() * 144);
  for (size_t t = 0; t < mesh.tets.size(); ++t) {
    const Element e = element(mesh, t, materials);
    const auto& q = mesh.tets[t];
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b) {
        double k3[3][3] = {};
        addBlock(e, a, b, k3);
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) trip.emplace_back(int(3 * q[size_t(a)]) + i, int(3 * q[size_t(b)]) + j, k3[i][j]);
      }
  }
  const int n = int(3 * mesh.positions.size());
  SpMat K(n, n);
  K.setFromTriplets(trip.begin(), trip.end());
  return {size_t(K.nonZeros()), K.sum()};
}

}  // namespace sprig::solids
