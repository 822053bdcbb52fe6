// The maps from a particle's step variable A = Δt Σ_i v_i (∇w_ip)^T to the strains a model's
// energy depends on (Appendix A), and the chain rule back to A:
//   F̂ = (I + A) G                          (5.12), G = F^n (or F_E^n: the elastic predictor)
//   Ŝ = K0 + A K1 + (A K1)^T + A K2 A^T     every b update of Chapters 4–5: (5.14), §4.6.1,
//                                            §4.6.2 and §4.7.1 (flow_strain_map_* below)
//   ε̂ = (A + A^T) / (2Δt)
// The transposed Jacobians act on a gradient C (3x3) as matrix maps: C G^T, (C + C^T) P^T with
// P = K1 + K2 A^T, and (C + C^T)/(2Δt). Ŝ is quadratic in A when K2 ≠ 0, so its Hessian gains
// the second-order term K2 ⊗ (G_S + G_S^T), G_S = ∂Ψ/∂S.
#pragma once

#include "viscompm/core/types.hpp"

namespace viscompm::materials {

/// Ŝ(A) = K0 + A K1 + (A K1)^T + A K2 A^T, with K0 and K2 symmetric.
struct FlowStrainMap {
  Mat3 K0 = Mat3::Identity();
  Mat3 K1 = Mat3::Identity();
  Mat3 K2 = Mat3::Zero();
  bool quadratic = false;  ///< K2 ≠ 0

  Mat3 predict(const Mat3& A) const {
    const Mat3 B = A * K1;
    Mat3 S = K0 + B + B.transpose();
    if (quadratic) {
      const Mat3 C = A * K2 * A.transpose();
      S += 0.5 * (C + C.transpose());  // symmetric to the last bit, so b stays exactly symmetric
    }
    return S;
  }
  /// P(A) = K1 + K2 A^T: dŜ = dA P + P^T dA^T.
  Mat3 jacobian_factor(const Mat3& A) const { return quadratic ? Mat3(K1 + K2 * A.transpose()) : K1; }
};

/// (5.14): Ŝ = S + A S + S A^T + (Δt/Wi)(I − S), linear in A.
inline FlowStrainMap flow_strain_map_paper(const Mat3& S, double dt, double weissenberg) {
  FlowStrainMap m;
  m.K0 = S + dt / weissenberg * (Mat3::Identity() - S);
  m.K1 = S;
  return m;
}

/// §4.6.1: (1 + Δt/Wi) Ŝ = (Δt/Wi) I + (I + A) S (I + A)^T, symmetric positive definite for all Δt.
inline FlowStrainMap flow_strain_map_spd(const Mat3& S, double dt, double weissenberg) {
  const double a = 1.0 / (1.0 + dt / weissenberg);
  FlowStrainMap m;
  m.K0 = a * (S + dt / weissenberg * Mat3::Identity());
  m.K1 = a * S;
  m.K2 = a * S;
  m.quadratic = true;
  return m;
}

/// §4.7.1: f̂ = (I + A) f + (Δt/2Wi)(f^{-T} − f) and Ŝ = f̂ f̂^T. With g = f + (Δt/2Wi)(f^{-T} − f),
/// f̂ = g + A f, so K0 = g g^T, K1 = f g^T, K2 = f f^T.
inline Mat3 predicted_fe_offset(const Mat3& f, double dt, double weissenberg) {
  return f + 0.5 * dt / weissenberg * (f.inverse().transpose() - f);
}
inline FlowStrainMap flow_strain_map_fe(const Mat3& f, double dt, double weissenberg) {
  const Mat3 g = predicted_fe_offset(f, dt, weissenberg);
  FlowStrainMap m;
  m.K0 = g * g.transpose();
  m.K1 = f * g.transpose();
  m.K2 = f * f.transpose();
  m.quadratic = true;
  return m;
}

/// §4.6.2: (1 + a) Ŝ = (I + A) S (I + A)^T + a (tr S / 3) I, with the plastic coefficient a ≥ 0
/// computed from the time-n strain.
inline FlowStrainMap flow_strain_map_herschel_bulkley(const Mat3& S, double plastic_coefficient) {
  const double c = 1.0 / (1.0 + plastic_coefficient);
  FlowStrainMap m;
  m.K0 = c * (S + plastic_coefficient * S.trace() / 3.0 * Mat3::Identity());
  m.K1 = c * S;
  m.K2 = c * S;
  m.quadratic = true;
  return m;
}

/// Q[(i,j),(m,n)] = M^{-1}_{jm} M^{-1}_{ni}, from M^{-1}: minus the derivative of M^{-T} with respect
/// to M (d(M^{-T}) = −M^{-T} dM^T M^{-T}).
inline Mat9 inverse_transpose_derivative(const Mat3& inverse) {
  Mat9 q;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int m = 0; m < 3; ++m)
        for (int n = 0; n < 3; ++n) q(vec_index(i, j), vec_index(m, n)) = inverse(j, m) * inverse(n, i);
  return q;
}

/// (K ⊗ M)(i + 3j, k + 3l) = K(j, l) M(i, k): the matrix of X ↦ M X K^T on vec(X).
inline Mat9 kronecker(const Mat3& K, const Mat3& M) {
  Mat9 out;
  for (int j = 0; j < 3; ++j)
    for (int l = 0; l < 3; ++l) out.block<3, 3>(3 * j, 3 * l) = K(j, l) * M;
  return out;
}

/// The chain rule from y = (F̂, Ŝ, ε̂) to A: left multiplication by the transposed Jacobian L_y^T
/// acts on each column of a 9×N matrix reshaped as a 3×3 matrix C.
struct StrainChainRule {
  enum class Strain { F, S, eps };
  Mat3 F_factor;   ///< G of F̂ = (I + A) G
  Mat3 S_factor;   ///< P(A) of dŜ = dA P + P^T dA^T
  double dt = 1.0;

  Mat3 pull_back(Strain y, const Mat3& C) const {
    switch (y) {
      case Strain::F: return C * F_factor.transpose();
      case Strain::S: return (C + C.transpose()) * S_factor.transpose();
      case Strain::eps: return (C + C.transpose()) / (2.0 * dt);
    }
    return C;
  }
  /// L_y^T X, column by column.
  Mat9 left(Strain y, const Mat9& X) const {
    Mat9 out;
    for (int k = 0; k < 9; ++k) out.col(k) = vec(pull_back(y, unvec(X.col(k))));
    return out;
  }
  /// L_a^T X L_b.
  Mat9 sandwich(Strain a, const Mat9& X, Strain b) const { return left(a, left(b, X.transpose()).transpose()); }
};

}  // namespace viscompm::materials
