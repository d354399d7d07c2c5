"""Neural models on NuScenesGraph (PyTorch): LaneGraphNet (nsgraph.models.lanegraphnet),
its training (python -m nsgraph.models.train), ONNX export (python -m nsgraph.models.export)
and prediction (nsgraph.models.predict). The post-processing runs in the C++ library."""
