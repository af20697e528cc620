# The skeleton and mesh as numpy arrays, saving through plant run's formats, determinism, the
# inline PNG, and the docs' example (docs/api.md, Python).
import re
import struct
import subprocess

import numpy as np
import pytest

import plant


def golden(rose):
    fields = {}
    for line in (rose.parent / "fig12c.mesh.txt").read_text().splitlines():
        key, *values = line.split()
        fields[key] = values
    return fields


def test_mesh_arrays(rose, tmp_path):
    p = plant.compile(rose).derive()
    m = p.mesh()
    assert m.vertices.dtype == np.float32 and m.vertices.ndim == 2 and m.vertices.shape[1] == 3
    assert m.normals.dtype == np.float32 and m.normals.shape == m.vertices.shape
    assert m.uvs.dtype == np.float32 and m.uvs.shape == (len(m.vertices), 2)
    assert m.indices.dtype == np.uint32 and m.indices.shape[1] == 3
    assert m.material.dtype == np.uint32 and m.material.shape == (len(m.indices),)
    assert m.group.dtype == np.int32 and m.group.shape == (len(m.indices),)
    assert m.colors.dtype == np.float32 and m.colors.shape == (len(m.textures), 3)
    assert m.indices.max() < len(m.vertices) and m.material.max() < len(m.colors)
    assert np.allclose(np.linalg.norm(m.normals, axis=1), 1, atol=1e-3)
    # every placed organ drawn out: the golden's instances, each a group of triangles
    g = golden(rose)
    assert len(m.group_names) == int(g["instances"][0])
    assert set(np.unique(m.group)) == set(range(-1, len(m.group_names)))
    # the bounds plant run reports, which the vertices reach
    want = np.array([float(v) for v in g["bounds"]]).reshape(2, 3)
    assert np.allclose(m.bounds, want, atol=1e-4)
    assert np.allclose(m.vertices.min(axis=0), want[0], atol=1e-4)
    assert np.allclose(m.vertices.max(axis=0), want[1], atol=1e-4)
    # as many vertices and triangles as plant run's OBJ, which draws every placement out too
    p.save(tmp_path / "rose.obj")
    obj = (tmp_path / "rose.obj").read_text().splitlines()
    assert len(m.vertices) == sum(1 for line in obj if line.startswith("v ")) == 93155
    assert len(m.indices) == sum(1 for line in obj if line.startswith("f ")) == 91552
    # fewer sides, fewer vertices
    assert len(p.mesh(sides=4).vertices) < len(m.vertices)
    with pytest.raises(ValueError):
        p.mesh(sides=2)


def test_skeleton_arrays(rose):
    p = plant.compile(rose).derive()
    s = p.skeleton()
    n = len(s.positions)
    assert s.positions.dtype == np.float64 and s.positions.shape == (n, 3)
    for name in ("headings", "lefts", "ups"):
        assert s[name].shape == (n, 3) and np.allclose(np.linalg.norm(s[name], axis=1), 1, atol=1e-6)
    assert s.radii.shape == (n,) and s.ids.dtype == np.uint64 and s.axis.dtype == np.int32
    axes = len(s.axis_parent)
    assert s.axis_start.shape == (axes + 1,) and s.axis_start[0] == 0 and s.axis_start[-1] == n
    assert np.all(np.diff(s.axis_start) >= 0)
    assert np.all(s.axis_parent < np.arange(axes)) and s.axis_parent[0] == -1
    assert s.organ_transforms.shape == (len(s.organ_ids), 4, 4)
    assert np.allclose(s.organ_transforms[:, 3, :], [0, 0, 0, 1])
    assert len(s.organ_names) == int(golden(rose)["instances"][0])
    assert "Skeleton(" in repr(s) and "positions=float64" in repr(s)


def test_save_glb_and_every_format(rose, tmp_path, plant_exe):
    p = plant.compile(rose).derive()
    out = tmp_path / "rose.glb"
    p.save(out, tmp_path / "rose.mesh.txt", tmp_path / "rose.txt")
    data = out.read_bytes()
    magic, version, length = struct.unpack("<4sII", data[:12])
    assert magic == b"glTF" and version == 2 and length == len(data)
    # the same bytes plant run writes
    subprocess.run([plant_exe, "run", str(rose), "-o", str(tmp_path / "cli.glb")], check=True)
    assert (tmp_path / "cli.glb").read_bytes() == data
    assert (tmp_path / "rose.mesh.txt").read_text() == (rose.parent / "fig12c.mesh.txt").read_text()
    assert (tmp_path / "rose.txt").read_text() == str(p) + "\n"
    p.save(tmp_path / "flat.glb", layout="flatten")
    assert (tmp_path / "flat.glb").read_bytes()[:4] == b"glTF"
    with pytest.raises(plant.ExportError, match="cannot tell the format"):
        p.save(tmp_path / "rose.xyz")
    with pytest.raises(plant.ExportError, match="cannot write"):
        p.save(tmp_path / "rose.glb" / "inside.glb")  # a file as a folder
    with pytest.raises(ValueError):
        p.save(out, layout="sideways")


def test_deterministic(rose):
    a = plant.compile(rose, seed=5).derive()
    b = plant.compile(rose, seed=5, threads=2).derive()
    c = plant.compile(rose, seed=6).derive()
    ma, mb, mc = a.mesh(), b.mesh(), c.mesh()
    for name in ("vertices", "normals", "uvs", "indices", "material", "group"):
        assert np.array_equal(ma[name], mb[name]), name
    assert ma.vertices.shape != mc.vertices.shape or not np.array_equal(ma.vertices, mc.vertices)
    assert np.array_equal(a.skeleton().positions, b.skeleton().positions)
    assert a.modules() == b.modules()


def test_show_is_an_inline_png(rose):
    img = plant.show(rose, size=(64, 48))
    assert isinstance(img, plant.Image)
    assert img._repr_png_()[:8] == b"\x89PNG\r\n\x1a\n"
    width, height = struct.unpack(">II", img.data[16:24])
    assert (width, height) == (64, 48)


def test_docs_example_runs(source_dir, rose, monkeypatch):
    text = (source_dir / "docs" / "api.md").read_text()
    section = text[text.index("## Python"):]
    blocks = re.findall(r"```python\n(.*?)```", section, re.S)
    assert blocks, "docs/api.md's Python section has no python example"
    monkeypatch.chdir(rose.parent)
    for code in blocks:
        exec(compile(code, "docs/api.md", "exec"), {})
    assert (rose.parent / "rose.glb").read_bytes()[:4] == b"glTF"
