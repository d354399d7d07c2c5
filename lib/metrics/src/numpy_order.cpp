// numpy's introsort for argsort (numpy/_core/src/npysort/quicksort.cpp `aquicksort_` and
// heapsort.cpp `aheapsort_`, numpy 1.22–1.24), written again from its rules: every swap
// and comparison in the same sequence, since the position of equal values is decided by
// nothing else.
#include "nsg/metrics/numpy_order.h"

#include <cmath>
#include <numeric>
#include <utility>

namespace nsg::metrics {
namespace {

// Below this many elements past the left end (pr − pl), numpy sorts by insertion.
constexpr std::ptrdiff_t kSmallQuicksort = 15;

// numpy's float "less": NaN after every number.
bool less(double a, double b) { return a < b || (b != b && a == a); }

// floor(log2 n) for n ≥ 1; 0 for n ≤ 1 (npy_get_msb).
int most_significant_bit(size_t n) {
  int depth = 0;
  while (n >>= 1) ++depth;
  return depth;
}

// aheapsort_ over idx[0, n): a max-heap on values, 1-based as numpy indexes it.
void heap_argsort(const std::vector<double>& v, size_t* idx, std::ptrdiff_t n) {
  size_t* a = idx - 1;  // a[1] … a[n]
  auto sift_down = [&](std::ptrdiff_t i, std::ptrdiff_t end, size_t held) {
    for (std::ptrdiff_t j = i * 2; j <= end;) {
      if (j < end && less(v[a[j]], v[a[j + 1]])) ++j;
      if (!less(v[held], v[a[j]])) break;
      a[i] = a[j];
      i = j;
      j += j;
    }
    a[i] = held;
  };
  for (std::ptrdiff_t l = n >> 1; l > 0; --l) sift_down(l, n, a[l]);
  while (n > 1) {
    const size_t held = a[n];
    a[n] = a[1];
    n -= 1;
    sift_down(1, n, held);
  }
}

// One quicksort partition of [pl, pr] around the median of three; returns the pivot's
// final position.
size_t* partition(const std::vector<double>& v, size_t* pl, size_t* pr) {
  size_t* pm = pl + ((pr - pl) >> 1);
  if (less(v[*pm], v[*pl])) std::swap(*pm, *pl);
  if (less(v[*pr], v[*pm])) std::swap(*pr, *pm);
  if (less(v[*pm], v[*pl])) std::swap(*pm, *pl);
  const double pivot = v[*pm];
  size_t* pi = pl;
  size_t* pj = pr - 1;
  std::swap(*pm, *pj);
  for (;;) {
    do {
      ++pi;
    } while (less(v[*pi], pivot));
    do {
      --pj;
    } while (less(pivot, v[*pj]));
    if (pi >= pj) break;
    std::swap(*pi, *pj);
  }
  std::swap(*pi, *(pr - 1));
  return pi;
}

void insertion_argsort(const std::vector<double>& v, size_t* pl, size_t* pr) {
  for (size_t* pi = pl + 1; pi <= pr; ++pi) {
    const size_t held = *pi;
    const double value = v[held];
    size_t* pj = pi;
    size_t* pk = pi - 1;
    while (pj > pl && less(value, v[*pk])) *pj-- = *pk--;
    *pj = held;
  }
}

struct Range {
  size_t* left;
  size_t* right;
  int depth_left;
};

}  // namespace

std::vector<size_t> numpy_argsort(const std::vector<double>& values) {
  std::vector<size_t> order(values.size());
  std::iota(order.begin(), order.end(), size_t{0});
  if (order.size() < 2) return order;
  std::vector<Range> stack;  // the larger partition waits: depth ≤ log2 n
  size_t* pl = order.data();
  size_t* pr = order.data() + order.size() - 1;
  int depth_left = most_significant_bit(order.size()) * 2;
  for (;;) {
    if (depth_left < 0) {
      heap_argsort(values, pl, pr - pl + 1);
    } else {
      while (pr - pl > kSmallQuicksort) {
        size_t* pi = partition(values, pl, pr);
        --depth_left;
        if (pi - pl < pr - pi) {
          stack.push_back({pi + 1, pr, depth_left});
          pr = pi - 1;
        } else {
          stack.push_back({pl, pi - 1, depth_left});
          pl = pi + 1;
        }
        // numpy checks the depth only when a range is taken up (its loop's head), so a
        // range keeps being partitioned here even once its depth is spent.
      }
      insertion_argsort(values, pl, pr);
    }
    if (stack.empty()) break;
    pl = stack.back().left;
    pr = stack.back().right;
    depth_left = stack.back().depth_left;
    stack.pop_back();
  }
  return order;
}

std::vector<size_t> numpy_argsort_descending(const std::vector<double>& values) {
  std::vector<double> negated(values.size());
  for (size_t i = 0; i < values.size(); ++i) negated[i] = -values[i];
  return numpy_argsort(negated);
}

}  // namespace nsg::metrics
