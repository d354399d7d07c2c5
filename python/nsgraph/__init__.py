"""nsgraph: NuScenesGraph from Python — read the dataset (numpy, PyTorch via
nsgraph.torch), score submissions (tiles, and per key frame with nsgraph.frames), build the paper's
adaptive ground truth. Everything
runs in the C++ library of the nsgraph toolkit (the _nsgraph extension)."""
from . import _nsgraph
from .dataset import LAYERS, MODALITIES, TILE_MEMBERS, Dataset
from .errors import ConfigError, DataError, Error, InternalError, IoError, ParseError, SubmissionError
from .groundtruth import adaptive_ground_truth
from .frames import score_frames
from .hosting import evaluate
from .scoring import check_submission, graph_arrays, score, score_tile, write_submission

__version__ = _nsgraph.__version__

__all__ = [
    "Dataset", "score_frames", "MODALITIES", "LAYERS", "TILE_MEMBERS", "score", "evaluate", "score_tile", "write_submission",
    "check_submission",
    "adaptive_ground_truth", "graph_arrays", "Error", "ParseError", "DataError", "ConfigError", "IoError",
    "InternalError", "SubmissionError",
]
