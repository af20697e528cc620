# pytest fixtures for the Python module's tests (docs/api.md, Python). Run by the ctest `python`
# with PYTHONPATH at build/python, and by tests/install/install.sh against an installed package:
#   PLANT_SOURCE_DIR  the folder holding grammars/ and docs/ (default: this file's ../..)
#   PLANT_EXE         a plant program to compare with (`plant derive`, `plant run -o`)
#   PLANT_EXPECT_PREFIX  when set, `import plant` must come from this install prefix
import os
import pathlib
import shutil

import pytest

SOURCE = pathlib.Path(os.environ.get("PLANT_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))


@pytest.fixture
def source_dir():
    return SOURCE


@pytest.fixture
def plant_exe():
    exe = os.environ.get("PLANT_EXE")
    if not exe:
        pytest.fail("PLANT_EXE names no plant program (tests/CMakeLists.txt sets it)")
    return exe


@pytest.fixture
def rose(tmp_path):
    """fig12c.plant copied into a scratch folder, with its golden counts (fig12c.mesh.txt)."""
    for name in ("fig12c.plant", "fig12c.mesh.txt"):
        shutil.copy(SOURCE / "grammars" / "rose" / name, tmp_path / name)
    return tmp_path / "fig12c.plant"
