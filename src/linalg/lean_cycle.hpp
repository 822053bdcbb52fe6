// The lean V-cycle (solver files: Cycle = lean): viscompm applies the fine level itself and hands
// the levels below to the MueLu hierarchy it built,
//   x = S r;  x += P · V₁(R (r − A x));  x += S (r − A x),
// with S the grid-line smoother (line_smoother.hpp), A the operator CG iterates with (assembled or
// matrix-free), P and R level 1's prolongator and restrictor and V₁ one MueLu V-cycle from level 1
// (Hierarchy::Iterate with startLevel 1). With Fine sweeps = k, the smoothing before and after the
// coarse correction is k sweeps x += S (r − A x) each (the first from x = 0). A fine level costs
// 2k products with A and 2k passes of line solves: no smoother containers, no level-0 smoother
// object in MueLu. With Fine smoother = Chebyshev the k steps before and after are instead the
// Chebyshev iteration of degree k preconditioned by the undamped line blocks B (Saad, Iterative
// Methods, Alg. 12.1; Ifpack2's Chebyshev with B for D): x += p(B A) B (r − A x), p the Chebyshev
// polynomial on [λ/ratio, λ] for λ = boost · λmax(B A), at the same cost as k sweeps. Symmetric
// (S and V₁ are, R = Pᵀ; p(BA)B is symmetric), so CG applies. Private to src/linalg.
#pragma once

#include <memory>

#include "line_smoother.hpp"
#include "linalg_types.hpp"

namespace viscompm::linalg {

/// The fine level's smoothing before and after the coarse correction.
struct FineSmoothing {
  int steps = 1;           ///< sweeps, or the Chebyshev degree
  bool chebyshev = false;  ///< Chebyshev steps rather than damped sweeps
  double ratio = 20.0;     ///< Chebyshev: λmax over the smallest eigenvalue it targets
  double boost = 1.1;      ///< Chebyshev: the estimated λmax is multiplied by this
};

class LeanCycle : public operator_type {
 public:
  LeanCycle(Teuchos::RCP<const operator_type> A, std::shared_ptr<const LineSmoother> smoother,
            Teuchos::RCP<muelu_hierarchy_type> hierarchy, const FineSmoothing& smoothing);

  Teuchos::RCP<const map_type> getDomainMap() const override { return A_->getDomainMap(); }
  Teuchos::RCP<const map_type> getRangeMap() const override { return A_->getRangeMap(); }
  void apply(const multivector_type& X, multivector_type& Y, Teuchos::ETransp mode = Teuchos::NO_TRANS,
             scalar_type alpha = Teuchos::ScalarTraits<scalar_type>::one(),
             scalar_type beta = Teuchos::ScalarTraits<scalar_type>::zero()) const override;

 private:
  Teuchos::RCP<const operator_type> A_;
  std::shared_ptr<const LineSmoother> smoother_;
  Teuchos::RCP<muelu_hierarchy_type> hierarchy_;
  FineSmoothing smoothing_;
  Teuchos::RCP<const crs_matrix_type> P_, R_;
};

}  // namespace viscompm::linalg
