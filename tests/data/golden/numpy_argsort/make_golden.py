#!/usr/bin/python3
"""Golden orders of numpy's default argsort (kind="quicksort"), ties included.

Made once, committed beside this script (cases.json), read by
tests/unit/metrics/test_numpy_order.cpp, which holds nsg::metrics::numpy_argsort to
numpy's own output on every case:

  /usr/bin/python3 make_golden.py      # Debian 12: python3-numpy 1.24.2

numpy 1.22-1.24 argsort float64 with the same introsort (median-of-three quicksort,
insertion sort below 17 values, heapsort past depth 2*floor(log2 n)); OpenLane-V2's
evaluator pins numpy < 1.24. The cases: small sizes around the insertion-sort cutoff, values
drawn from few distinct ones (many ties), all-equal, sorted, reversed, signed zeros, NaN,
and arrays built by McIlroy's adversary ("A killer adversary for quicksort", 1999) that
drive the quicksort past its depth limit into heapsort, with their largest quarter made
equal. Each case records whether numpy's order differs from a stable sort's, so the test
can count that ties were really exercised.
"""
import json
import os
import random

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))


def adversary(n):
    """McIlroy's adversary against numpy's quicksort partitioning: values decided lazily
    ("gas" until compared) so that every median-of-three pivot is near the bottom."""
    val = [None] * n
    state = {"solid": 0, "candidate": None}

    def less(x, y):
        if val[x] is None and val[y] is None:
            frozen = x if x == state["candidate"] else y
            val[frozen] = state["solid"]
            state["solid"] += 1
        if val[x] is None:
            state["candidate"] = x
        elif val[y] is None:
            state["candidate"] = y
        return (n if val[x] is None else val[x]) < (n if val[y] is None else val[y])

    idx = list(range(n))
    stack, pl, pr = [], 0, n - 1
    depth = (n.bit_length() - 1) * 2
    reached_heapsort = False
    while True:
        if depth < 0:
            reached_heapsort = True  # the values below this range no longer matter
        else:
            while pr - pl > 15:
                pm = pl + ((pr - pl) >> 1)
                if less(idx[pm], idx[pl]):
                    idx[pm], idx[pl] = idx[pl], idx[pm]
                if less(idx[pr], idx[pm]):
                    idx[pr], idx[pm] = idx[pm], idx[pr]
                if less(idx[pm], idx[pl]):
                    idx[pm], idx[pl] = idx[pl], idx[pm]
                pivot, pi, pj = idx[pm], pl, pr - 1
                idx[pm], idx[pj] = idx[pj], idx[pm]
                while True:
                    pi += 1
                    while less(idx[pi], pivot):
                        pi += 1
                    pj -= 1
                    while less(pivot, idx[pj]):
                        pj -= 1
                    if pi >= pj:
                        break
                    idx[pi], idx[pj] = idx[pj], idx[pi]
                idx[pi], idx[pr - 1] = idx[pr - 1], idx[pi]
                depth -= 1
                if pi - pl < pr - pi:
                    stack.append((pi + 1, pr, depth))
                    pr = pi - 1
                else:
                    stack.append((pl, pi - 1, depth))
                    pl = pi + 1
        if not stack:
            break
        pl, pr, depth = stack.pop()
    for i in range(n):
        if val[i] is None:
            val[i] = state["solid"]
            state["solid"] += 1
    assert reached_heapsort, n
    return [float(v) for v in val]


def cases():
    rnd = random.Random(20261207)
    out = []

    def add(name, values):
        out.append((name, [float(v) for v in values]))
    for n in range(0, 40):
        add("few-values-%d" % n, [rnd.randint(0, 2) / 10 for _ in range(n)])
    for n in (50, 64, 100, 129, 300, 1000):
        for k in (1, 2, 5, 50):
            add("n%d-values%d" % (n, k), [rnd.randint(0, k - 1) / 8 for _ in range(n)])
        add("n%d-sorted-ties" % n, sorted(rnd.randint(0, 9) for _ in range(n)))
        add("n%d-reversed-ties" % n, sorted((rnd.randint(0, 9) for _ in range(n)), reverse=True))
        add("n%d-signed-zeros" % n, [0.0 if i % 3 else -0.0 for i in range(n)])
        add("n%d-nan" % n, [float("nan") if rnd.random() < 0.2 else rnd.randint(0, 3) for _ in range(n)])
    for n in (100, 257, 1000):
        values = adversary(n)
        add("adversary-%d" % n, values)
        cut = sorted(values)[-(n // 4)]
        add("adversary-%d-top-quarter-tied" % n, [v if v < cut else float(n * 10) for v in values])
    return out


def main():
    doc = {"made_by": "make_golden.py: numpy %s np.argsort(values) (kind quicksort), float64" % np.__version__,
           "cases": []}
    for name, values in cases():
        a = np.array(values, dtype=np.float64)
        order = np.argsort(a).tolist()
        stable = np.argsort(a, kind="stable").tolist()
        doc["cases"].append({"name": name, "values": [None if v != v else v for v in values],
                             "numpy_argsort": order, "differs_from_stable": order != stable})
    with open(os.path.join(HERE, "cases.json"), "w") as f:
        json.dump(doc, f, separators=(",", ":"))
        f.write("\n")
    print(len(doc["cases"]), "cases,", sum(c["differs_from_stable"] for c in doc["cases"]), "differ from stable")


if __name__ == "__main__":
    main()
