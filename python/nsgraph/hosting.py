"""Hosting a leaderboard: ``nsgraph.evaluate`` in the form EvalAI-style challenge servers
call an evaluation script (``evaluate(test_annotation_file, user_submission_file,
phase_codename, **kwargs)``). Scoring is ``nsgraph.score``: the same checks and limits as
``nsgraph score``."""
from .frames import score_frames
from .scoring import METRICS, score

# The leaderboard's default columns: the report's per-tile means of the metrics the C++ table
# marks `leaderboard` (metrics::metric_info; docs/metrics.md "Metric list"), in its order.
LEADERBOARD_METRICS = tuple(m["name"] for m in METRICS if m["leaderboard"])


def evaluate(test_annotation_file, user_submission_file, phase_codename, **kwargs):
    """Scores ``user_submission_file`` against ``test_annotation_file`` (what ``nsgraph
    score --ground-truth`` takes: a dataset folder or a ground-truth file in the submission
    format) and returns ``{"result": [{split: {metric: value}}], "submission_result":
    {metric: value}}`` as EvalAI expects; an undefined mean is None.

    kwargs: ``split`` (the dataset split scored, default "test"), ``split_codename`` (the
    key in ``result``, default the split), ``metrics`` (names of the report's means, default
    LEADERBOARD_METRICS), ``max_seconds`` (the scoring's wall-clock budget, default 3600 as
    ``nsgraph score --max-seconds``; ConfigError beyond it); others (``submission_metadata``,
    …) are ignored. Raises SubmissionError (with .issues) for a submission ``nsgraph score``
    refuses.
    """
    split = kwargs.get("split") or "test"
    codename = kwargs.get("split_codename") or split
    if kwargs.get("paradigm") == "frames" or str(phase_codename).startswith("frames"):
        return _evaluate_frames(test_annotation_file, user_submission_file, split, codename,
                                kwargs.get("max_seconds", 3600))
    names = kwargs.get("metrics") or LEADERBOARD_METRICS
    report = score(test_annotation_file, user_submission_file, split=split,
                   max_seconds=kwargs.get("max_seconds", 3600))
    mean = report["aggregate"]["mean"]
    values = {name: mean.get(name) for name in names}
    values["n_tiles"] = report["aggregate"]["n_tiles"]
    values["n_missing_predictions"] = report["aggregate"]["n_missing_predictions"]
    del phase_codename  # one benchmark: every phase scores the same way
    return {"result": [{codename: values}], "submission_result": values}


def _evaluate_frames(test_annotation_file, user_submission_file, split, codename, max_seconds):
    report = score_frames(test_annotation_file, user_submission_file, split=split, max_seconds=max_seconds)
    values = {name: report[name] for name in ("DET_l", "TOP_ll", "lane_score")}
    if report.get("lane_segments"):  # the lane-segment track's, when the results carry lane segments
        values.update({name: report["lane_segments"][name] for name in ("DET_ls", "DET_a", "TOP_lsls")})
        values["ls_score"] = report["lane_segments"]["score"]
    values["n_frames"] = report["counts"]["frames"]
    values["n_missing_frames"] = report["counts"]["missing_frames"]
    return {"result": [{codename: values}], "submission_result": values}
