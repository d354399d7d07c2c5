// The order in which numpy's default argsort puts values, ties included.
//
// OpenLane-V2's evaluator ranks predictions with `np.argsort(-confidence)`: numpy's default
// kind, "quicksort", is an introsort (median-of-three quicksort, insertion sort below 17
// values, heapsort past a depth of 2·floor(log2 n)) and is not stable: equal confidences
// come out in an order that depends on the whole array. To give the evaluator's numbers on
// submissions with equal confidences, frames scoring ranks exactly as that algorithm does —
// the one of numpy 1.22–1.24 (OpenLane-V2 pins numpy < 1.24; Debian 12 has 1.24.2, the
// same code). numpy ≥ 1.25 on AVX-512 machines argsorts 64-bit values with x86-simd-sort
// instead, which may order ties differently (docs/metrics.md "Frames", Ties).
#pragma once

#include <cstddef>
#include <vector>

namespace nsg::metrics {

// np.argsort(values, kind="quicksort") for float64 values: indices in ascending order.
// NaN sorts last, as numpy's float comparison puts it.
std::vector<size_t> numpy_argsort(const std::vector<double>& values);

// np.argsort(-values): the evaluator's "by descending confidence".
std::vector<size_t> numpy_argsort_descending(const std::vector<double>& values);

}  // namespace nsg::metrics
