// An affine map of 3D space in double precision: glTF's node transforms, composed down the node
// tree before the vertices are moved (in float only once, at the end).
#pragma once

#include <array>
#include <cmath>

#include "math/vec.hpp"

namespace tracer {

struct Affine {
  // Rows of [linear | translation].
  std::array<std::array<double, 4>, 3> m{{{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}}};

  // From a column-major 4x4 matrix (glTF's and OpenGL's order); the bottom row is dropped.
  static Affine from_column_major(const double* c) {
    Affine a;
    for (int r = 0; r < 3; ++r)
      for (int k = 0; k < 4; ++k) a.m[r][k] = c[4 * k + r];
    return a;
  }
  // As a column-major 4x4 matrix, the bottom row (0, 0, 0, 1): from_column_major's inverse.
  std::array<double, 16> column_major() const {
    std::array<double, 16> c{};
    for (int r = 0; r < 3; ++r)
      for (int k = 0; k < 4; ++k) c[size_t(4 * k + r)] = m[size_t(r)][size_t(k)];
    c[15] = 1.0;
    return c;
  }
  // Translation T, rotation R (a unit quaternion x, y, z, w) and scale S, as T * R * S.
  static Affine from_trs(const double* t, const double* q, const double* s) {
    const double x = q[0], y = q[1], z = q[2], w = q[3];
    const double r[3][3] = {{1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)},
                            {2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)},
                            {2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)}};
    Affine a;
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) a.m[i][j] = r[i][j] * s[j];
      a.m[i][3] = t[i];
    }
    return a;
  }
  // This map after `inner`: (*this)(inner(p)).
  Affine operator*(const Affine& inner) const {
    Affine out;
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 4; ++j) {
        double v = j == 3 ? m[i][3] : 0.0;
        for (int k = 0; k < 3; ++k) v += m[i][k] * inner.m[k][j];
        out.m[i][j] = v;
      }
    }
    return out;
  }
  Vec3 point(Vec3 p) const {
    return {float(m[0][0] * p.x + m[0][1] * p.y + m[0][2] * p.z + m[0][3]),
            float(m[1][0] * p.x + m[1][1] * p.y + m[1][2] * p.z + m[1][3]),
            float(m[2][0] * p.x + m[2][1] * p.y + m[2][2] * p.z + m[2][3])};
  }
  Vec3 vector(Vec3 v) const {
    return {float(m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z), float(m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z),
            float(m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z)};
  }
  double determinant() const {
    return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
           m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
  }
  // Normals move by the inverse transpose of the linear part; the cofactor matrix is that times
  // the determinant, whose magnitude the normalisation after drops (its sign is kept by the caller).
  Vec3 normal(Vec3 n) const {
    const auto c = [&](int r0, int c0, int r1, int c1) { return m[r0][c0] * m[r1][c1] - m[r0][c1] * m[r1][c0]; };
    const double cof[3][3] = {{c(1, 1, 2, 2), -c(1, 0, 2, 2), c(1, 0, 2, 1)},
                              {-c(0, 1, 2, 2), c(0, 0, 2, 2), -c(0, 0, 2, 1)},
                              {c(0, 1, 1, 2), -c(0, 0, 1, 2), c(0, 0, 1, 1)}};
    return {float(cof[0][0] * n.x + cof[0][1] * n.y + cof[0][2] * n.z),
            float(cof[1][0] * n.x + cof[1][1] * n.y + cof[1][2] * n.z),
            float(cof[2][0] * n.x + cof[2][1] * n.y + cof[2][2] * n.z)};
  }
  // The inverse map (the caller checks the determinant is not zero): the linear part's adjugate
  // over its determinant, and the translation moved back through it.
  Affine inverse() const {
    const auto c = [&](int r0, int c0, int r1, int c1) { return m[r0][c0] * m[r1][c1] - m[r0][c1] * m[r1][c0]; };
    const double inv_det = 1.0 / determinant();
    Affine out;
    const double adj[3][3] = {{c(1, 1, 2, 2), -c(0, 1, 2, 2), c(0, 1, 1, 2)},
                              {-c(1, 0, 2, 2), c(0, 0, 2, 2), -c(0, 0, 1, 2)},
                              {c(1, 0, 2, 1), -c(0, 0, 2, 1), c(0, 0, 1, 1)}};
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) out.m[i][j] = adj[i][j] * inv_det;
      out.m[i][3] = -(out.m[i][0] * m[0][3] + out.m[i][1] * m[1][3] + out.m[i][2] * m[2][3]);
    }
    return out;
  }
  bool finite() const {
    for (const auto& row : m)
      for (double v : row)
        if (!std::isfinite(v)) return false;
    return true;
  }
};

}  // namespace tracer
