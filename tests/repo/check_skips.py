"""Only an optional tool may skip a test; missing test data is a failure.

Reads ctest's log (build/Testing/Temporary/LastTest.log), finds every skipped GoogleTest
test and every skipped Python unittest, and fails unless the skip's reason starts with
"optional " (e.g. "optional tool gdalinfo not installed", "optional hardware: no AVX2").
`make test` runs it after ctest, so CI fails on any other skip.

  check_skips.py LOG          exit 0 if every skip is allowed, 1 with the list otherwise
  check_skips.py --self-test  checks the parser on small made-up logs
"""
import re
import sys

ALLOWED_PREFIX = "optional "
# GoogleTest: "<file>:<line>: Skipped" then the message, up to "[  SKIPPED ] Suite.Test".
GTEST_SKIP = re.compile(r"^[^\n]*: Skipped\n(.*?)\n?\[  SKIPPED \] ([\w/.]+)", re.S | re.M)
# Python unittest (verbosity 2): "test_name (module.Class...) ... skipped 'reason'".
PY_SKIP = re.compile(r"^(test\w*) \(([\w.]+)\)[^\n]*?\.\.\. skipped ['\"](.*)['\"]$", re.M)


def skips(log_text):
    """(test, reason) for every skip in the log."""
    found = [(name, reason.strip()) for reason, name in GTEST_SKIP.findall(log_text)]
    found += [(where, reason.strip()) for _, where, reason in PY_SKIP.findall(log_text)]
    return found


def disallowed(log_text):
    return [(t, r) for t, r in skips(log_text) if not r.startswith(ALLOWED_PREFIX)]


def self_test():
    log = (
        "[ RUN      ] GeoTiff.GdalReadsIt\n/src/x.cpp:227: Skipped\noptional tool gdalinfo not installed\n\n"
        "[  SKIPPED ] GeoTiff.GdalReadsIt (0 ms)\n"
        "[ RUN      ] Real.KeyFrame\n/src/y.cpp:12: Skipped\nno tests/data/real\n\n[  SKIPPED ] Real.KeyFrame (0 ms)\n"
        "test_a (test_x.T.test_a) ... skipped 'optional tool chromium not installed'\n"
        "test_b (test_x.T.test_b) ... skipped 'fixture missing'\n"
        "test_c (test_x.T.test_c) ... ok\n")
    got = skips(log)
    want = [("GeoTiff.GdalReadsIt", "optional tool gdalinfo not installed"), ("Real.KeyFrame", "no tests/data/real"),
            ("test_x.T.test_a", "optional tool chromium not installed"), ("test_x.T.test_b", "fixture missing")]
    if got != want:
        sys.exit(f"self-test: parsed {got}, expected {want}")
    bad = [t for t, _ in disallowed(log)]
    if bad != ["Real.KeyFrame", "test_x.T.test_b"]:
        sys.exit(f"self-test: flagged {bad}")
    print("self-test: 4 skips parsed, the 2 not for an optional tool flagged")
    return 0


def main(argv):
    if argv[1:] == ["--self-test"]:
        return self_test()
    if len(argv) != 2:
        print(__doc__, file=sys.stderr)
        return 2
    try:
        with open(argv[1], encoding="utf-8", errors="replace") as f:
            text = f.read()
    except OSError as e:
        print(f"{argv[1]}: cannot read the ctest log: {e.strerror}", file=sys.stderr)
        return 2
    all_skips = skips(text)
    bad = disallowed(text)
    for test, reason in bad:
        print(f"{test}: skipped for a reason other than an optional tool: {reason!r}")
    print(f"{len(all_skips)} skipped tests, {len(bad)} not allowed "
          f"(a skip's reason must start with {ALLOWED_PREFIX!r})")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
