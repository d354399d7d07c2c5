"""nsgraph.Dataset: random access to the tiles of one split, decoded in C++."""
import collections.abc
import os

from . import _nsgraph

# A tile's members as the C++ library declares them (io/tile_members.h): name, file,
# raster, dtype, bands, unit, nodata, coverage_bit, description.
TILE_MEMBERS = _nsgraph.TILE_MEMBERS
# The semantic layer's classes, id order: {"id", "name", "color"}; SEMANTIC_VOID = no class.
SEMANTIC_CLASSES = _nsgraph.SEMANTIC_CLASSES
SEMANTIC_VOID = _nsgraph.SEMANTIC_VOID
# The codes of a tile graph's turn and junction arrays, by their graph.json names.
TURNS = _nsgraph.TURNS
JUNCTIONS = _nsgraph.JUNCTIONS
# A map-update dataset's edge labels (graph["change"] codes; 0 = "" outside such a dataset).
MAP_CHANGES = _nsgraph.MAP_CHANGES
LAYERS = {m["name"]: m for m in TILE_MEMBERS if m["raster"]}
# The input layers (every raster but the coverage flags, which are always read).
MODALITIES = tuple(name for name in LAYERS if name != "coverage")


def _modalities(value):
    """A tuple of layer names from "all", "lidar", "lidar,rgb" or a list of names."""
    if isinstance(value, str):
        return MODALITIES if value == "all" else tuple(m.strip() for m in value.split(",") if m.strip())
    return tuple(value)


class Dataset(collections.abc.Sequence):
    """The tiles of one split of a NuScenesGraph dataset (tar shards or folder layout).

    ``ds[i]`` is a dict::

        key, shard                     str
        lidar     uint8   (H, W)       0 = no data
        rgb       uint8   (H, W, 3)    0, 0, 0 = no data
        semantic  uint8   (H, W)       255 = no data
        vehicle   float32 (H, W)       heading / 2π clockwise from north in [0, 1), -1 = none
        coverage  uint8   (H, W)       bit flags 1 LiDAR, 2 RGB, 4 semantics
        graph     {nodes_px (N, 2) float64 u, v;  nodes_m (N, 2) float64 x, y;
                   edges (E, 2) int64 node indices;  lane_tokens [E str];  node_ids (N,) int64;
                   junction (N,) int64 into JUNCTIONS;  turn (E,) int64 into TURNS;
                   connector, in_intersection (E,) bool;  lane_changes (C, 2) int64 node
                   indices;  lane_change_tokens [C (from, to)];  change (E,) int64 into
                   MAP_CHANGES}  (docs/dataset-format.md)
        prior_graph  a map-update dataset's (generate's splits.preset map-update): the prior
                   map's graph of the tile, as graph
        meta      the tile's meta.json as a dict

    ``ds[i]`` by position or ``ds[key]`` / ``ds.get(key)`` by tile key (``ds.keys``).
    ``rung``: a dataset with an observation ladder (``generate --ladder``) has the split's
    tiles again as seen by the first k scenes; ``rung=k`` reads those (keys
    ``<key>-r<k>``, ``meta["ladder"]`` says which scenes), ``None`` or ``"all"`` the
    split's own tiles. ``Dataset.rungs(root)`` lists the rungs a dataset has.
    ``modalities``: "all", one name, a comma list ("lidar,rgb") or a list of names.
    Only the requested ``modalities`` are read (coverage always). Shards are indexed once
    per process (member offsets), tiles are read with positioned reads and decoded in C++
    without the GIL: safe and parallel in DataLoader workers (fork or spawn).
    """

    def __init__(self, root, split, modalities=MODALITIES, graph=True, meta=True, rung=None):
        modalities = _modalities(modalities)
        if rung == "all":
            rung = None
        if rung is not None and (isinstance(rung, bool) or not isinstance(rung, int) or rung < 1):
            from .errors import ConfigError
            raise ConfigError(f"rung: {rung!r}; expected a scene count >= 1, \"all\" or None")
        unknown = [m for m in modalities if m not in MODALITIES]
        if unknown:
            from .errors import ConfigError
            raise ConfigError(f"modalities: {unknown} unknown; expected a subset of {MODALITIES}")
        self.root = os.fspath(root)
        self.split = split
        self.modalities = modalities
        self.graph = graph
        self.meta = meta
        self.rung = rung
        # A rung is read as its split name, "<split>-r<k>" (io::rung_split), as every command does.
        self._index = _nsgraph.SplitIndex(self.root, f"{split}-r{rung}" if rung else split)
        self._layers = list(modalities) + ["coverage"]

    def __len__(self):
        return len(self._index)

    def __getitem__(self, i):
        if isinstance(i, slice):
            return [self[j] for j in range(*i.indices(len(self)))]
        if isinstance(i, str):
            try:
                return self[self.index(i)]
            except ValueError as e:
                raise KeyError(str(e)) from None
        n = len(self)
        if i < 0:
            i += n
        if not 0 <= i < n:
            raise IndexError(f"tile index {i} out of range for {n} tiles of split '{self.split}'")
        return self._index.read(i, self._layers, self.graph, self.meta)

    @staticmethod
    def rungs(root):
        """The observation ladder's built rungs of the dataset at ``root`` (scene counts,
        ascending; the split's own tiles are rung "all"); [] without a ladder."""
        return list(_nsgraph.dataset_rungs(os.fspath(root)))

    def key(self, i):
        return self._index.key(i)

    def shard(self, i):
        """Manifest name of the shard holding tile i ("train-000000")."""
        return self._index.shard_name(i)

    @property
    def keys(self):
        """The tile keys of the split, in dataset order (``ds[key]`` and ``ds.get(key)`` take them)."""
        return [self._index.key(i) for i in range(len(self))]

    def _positions(self):
        if not hasattr(self, "_by_key"):
            self._by_key = {k: i for i, k in enumerate(self.keys)}
        return self._by_key

    def index(self, key, *args):
        """The position of tile ``key`` (no tile is decoded); ValueError naming the split when
        it is not one of its tiles."""
        try:
            return self._positions()[key]
        except (KeyError, TypeError):
            example = self.key(0) if len(self) else "none"
            raise ValueError(f"{key!r} is not a tile of split '{self.split}' ({len(self)} tiles, e.g. "
                             f"{example!r})") from None

    def __contains__(self, key):
        return isinstance(key, str) and key in self._positions()

    def get(self, key, default=None):
        """``ds[key]``, or ``default`` when ``key`` is not a tile of the split."""
        return self[self._positions()[key]] if key in self else default

    def member_bytes(self, i, suffix):
        """Raw bytes of one member of tile i ("lidar.tif", "graph.json", ...)."""
        return self._index.read_member(i, suffix)

    # Pickled by arguments (spawned DataLoader workers): the index is rebuilt, from the
    # per-process cache when the shards were indexed before.
    def __getstate__(self):
        return {"root": self.root, "split": self.split, "modalities": self.modalities,
                "graph": self.graph, "meta": self.meta, "rung": self.rung}

    def __setstate__(self, state):
        self.__init__(**state)

    def __repr__(self):
        return (f"nsgraph.Dataset({self.root!r}, {self.split!r}, modalities={self.modalities}) "
                f"with {len(self)} tiles")
