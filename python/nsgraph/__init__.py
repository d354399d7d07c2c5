"""nsgraph: NuScenesGraph from Python — read the dataset (numpy, PyTorch via
nsgraph.torch), score submissions (tiles, and per key frame with nsgraph.frames), build the paper's
adaptive ground truth. Everything
runs in the C++ library of the nsgraph toolkit (the _nsgraph extension)."""
try:
    import numpy as _numpy  # noqa: F401  (the modules below return and take numpy arrays)
except ImportError as _error:
    import sys as _sys
    raise ImportError(
        f"nsgraph needs numpy, and this interpreter ({_sys.executable}, Python {_sys.version.split()[0]}) "
        f"has none: {_error}. Debian's /usr/bin/python3 has it (apt-get install python3-numpy); in a venv, "
        f"`pip install numpy` from an index or a wheelhouse, or on CPython 3.11 make Debian's packages "
        f"visible (docs/python.md, 'Other interpreters').") from _error
try:
    from . import _nsgraph
except ImportError as _error:  # most often: another interpreter than the extension was built for
    import glob as _glob
    import os as _os
    import sys as _sys
    _built = [_os.path.basename(p) for p in _glob.glob(_os.path.join(_os.path.dirname(__file__), "_nsgraph*.so"))]
    raise ImportError(
        f"nsgraph's C++ extension cannot be loaded by this interpreter ({_sys.executable}, Python "
        f"{_sys.version.split()[0]}): {_error}. The extension here is {', '.join(_built) or 'missing'}; it runs "
        f"with the interpreter it was built for (Debian's /usr/bin/python3 for `make`) — use that one, or "
        f"rebuild (cmake --build build --target nsgraph_python) with this one.") from _error
from .dataset import JUNCTIONS, LAYERS, MAP_CHANGES, MODALITIES, SEMANTIC_CLASSES, SEMANTIC_VOID, TILE_MEMBERS, TURNS, Dataset
from .errors import ConfigError, DataError, Error, InternalError, IoError, ParseError, SubmissionError
from .graphify import graphify
from .groundtruth import adaptive_ground_truth
from .frames import score_frames
from .hosting import evaluate
from .scoring import HEADLINE_METRICS, METRICS, check_submission, graph_arrays, score, score_tile, write_submission

__version__ = _nsgraph.__version__

__all__ = [
    "Dataset", "score_frames", "MODALITIES", "LAYERS", "TILE_MEMBERS", "SEMANTIC_CLASSES", "SEMANTIC_VOID", "TURNS", "JUNCTIONS", "MAP_CHANGES", "METRICS", "HEADLINE_METRICS", "score", "evaluate", "score_tile", "write_submission",
    "check_submission",
    "adaptive_ground_truth", "graphify", "graph_arrays", "Error", "ParseError", "DataError", "ConfigError", "IoError",
    "InternalError", "SubmissionError",
]
