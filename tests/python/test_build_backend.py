"""The in-tree build backend's metadata follows pyproject.toml: Requires-Dist and the extras
are read from [project] and [project.optional-dependencies], not written into the backend,
and a malformed array is a BuildError naming the key."""
import os
import shutil
import sys
import tempfile
import unittest

import fixtures

sys.path.insert(0, os.path.join(fixtures.SOURCE_DIR, "python", "build_backend"))
import nsgraph_build  # noqa: E402


def fake_project(pyproject):
    root = tempfile.mkdtemp(prefix="nsg-backend-")
    with open(os.path.join(root, "pyproject.toml"), "w") as f:
        f.write(pyproject)
    with open(os.path.join(root, "CMakeLists.txt"), "w") as f:
        f.write("project(nsgraph VERSION 9.8.7 LANGUAGES CXX)\n")
    return root


class BuildBackendTest(unittest.TestCase):
    def metadata(self, root):
        saved = nsgraph_build.ROOT
        nsgraph_build.ROOT = root
        try:
            return nsgraph_build._metadata().splitlines()
        finally:
            nsgraph_build.ROOT = saved

    def test_the_repositorys_metadata_says_what_pyproject_says(self):
        lines = self.metadata(fixtures.SOURCE_DIR)
        self.assertIn("Requires-Dist: numpy", lines)
        self.assertIn("Provides-Extra: torch", lines)
        self.assertIn('Requires-Dist: torch; extra == "torch"', lines)

    def test_other_dependencies_reach_the_metadata(self):
        root = fake_project('[project]\nname = "nsgraph"\nrequires-python = ">=3.9"\n'
                            'dependencies = [\n  "numpy>=1.22",\n  "pillow",\n]\n\n'
                            '[project.optional-dependencies]\ntorch = ["torch>=2.0"]\nviz = ["matplotlib"]\n')
        try:
            lines = self.metadata(root)
        finally:
            shutil.rmtree(root)
        self.assertIn("Version: 9.8.7", lines)
        self.assertEqual([l for l in lines if l.startswith("Requires-Dist") and "extra" not in l],
                         ["Requires-Dist: numpy>=1.22", "Requires-Dist: pillow"])
        self.assertIn('Requires-Dist: matplotlib; extra == "viz"', lines)
        self.assertIn('Requires-Dist: torch>=2.0; extra == "torch"', lines)

    def test_a_malformed_array_names_the_key(self):
        root = fake_project('[project]\nname = "nsgraph"\ndependencies = [numpy]\n')
        try:
            with self.assertRaises(nsgraph_build.BuildError) as e:
                self.metadata(root)
        finally:
            shutil.rmtree(root)
        self.assertIn("project.dependencies", str(e.exception))


if __name__ == "__main__":
    unittest.main()
