"""plant from Python: compile a ``.plant`` grammar, derive it, read the string, the skeleton and
the mesh as numpy arrays, and write any format ``plant run -o`` writes (docs/api.md, Python).

    import plant
    rose = plant.compile("fig12c.plant", seed=3).derive()
    mesh = rose.mesh()            # mesh.vertices: float32 (V, 3), mesh.indices: uint32 (T, 3), ...
    rose.save("rose.glb")
"""

import math
import numbers
import os
import sys

from . import _paths
from ._errors import CompileError, DeriveError, Diagnostic, Error, ExportError
from ._plant import compile as _compile
from ._types import Arrays, Image, Module

__all__ = [
    "compile", "show", "Plant", "Module", "Image", "Arrays",
    "Error", "CompileError", "DeriveError", "ExportError", "Diagnostic", "STDLIB",
]

# The standard library this package reads `import rose;` from: the source tree's stdlib/ in the
# build tree, PREFIX/share/plant/stdlib once installed (found from this folder, so a moved
# install reads its own).
STDLIB = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), _paths.STDLIB))

_LAYOUTS = ("instanced", "nodes", "flatten")


def _is_path(source):
    if isinstance(source, os.PathLike):
        return True
    return "\n" not in source and source.strip().endswith(".plant")


def _param_text(name, value):
    if isinstance(value, str):
        return value  # an expression, as after plant run -D name=
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError("params[%r]: expected a number or an expression string, got %s"
                        % (name, type(value).__name__))
    if isinstance(value, numbers.Integral):
        return str(int(value))
    value = float(value)
    if not math.isfinite(value):
        raise ValueError("params[%r]: %r is not a finite number" % (name, value))
    return repr(value)


def _dirs(dirs):
    if dirs is None:
        return []
    if isinstance(dirs, (str, os.PathLike)):
        dirs = [dirs]
    return [os.fspath(d) for d in dirs]


def compile(source, params=None, seed=None, steps=None, allow_read=None, include=None,
            threads=1, max_modules=50_000_000, name=None):
    """Compiles a grammar and starts its derivation (at step 0: the axiom).

    ``source`` is a path (a ``pathlib.Path``, or a one-line string ending in ``.plant``) or the
    grammar's text (anything else; its diagnostics name it ``name``, by default ``<string>``, and
    it reads files relative to the current folder). ``params`` overrides ``param`` declarations
    (numbers, or expression strings as ``plant run -D``); ``seed`` and ``steps`` override the
    grammar's ``seed S;`` and ``derive N;``. As with the plant command a grammar reads files
    (imports, ``load(...)``, meshes) only from its own folder, ``include`` folders, ``PLANT_PATH``
    and the standard library; ``allow_read`` lists more folders. ``threads`` rewrites in parallel
    without changing the result. Raises :class:`CompileError` with the diagnostics.
    """
    defines = [(str(k), _param_text(k, v)) for k, v in (params or {}).items()]
    if seed is not None and not (isinstance(seed, numbers.Integral) and 0 <= seed < 2**64):
        raise ValueError("seed must be a whole number from 0 to 2**64 - 1, got %r" % (seed,))
    if steps is not None and not (isinstance(steps, numbers.Integral) and 0 <= steps <= 1_000_000):
        raise ValueError("steps must be a whole number from 0 to 1000000, got %r" % (steps,))
    if _is_path(source):
        label, text = os.fspath(source), None
    else:
        label, text = (name or "<string>"), source
    includes = _dirs(include) + [STDLIB]
    core = _compile(label, text, defines, includes, _dirs(allow_read),
                    None if seed is None else int(seed), None if steps is None else int(steps),
                    int(threads), int(max_modules))
    return Plant(core, label)


class Plant:
    """A compiled grammar and its derivation; made by :func:`compile`."""

    def __init__(self, core, name):
        self._core = core
        self.name = name

    def derive(self, n=None):
        """Derives ``n`` more steps, or all the remaining ones (up to ``steps=`` or the grammar's
        ``derive N;``); the ``on end`` hook runs once the last is done. Returns the plant. Output
        of ``print(...)`` in hooks goes to ``sys.stderr``. Raises :class:`DeriveError`."""
        try:
            self._core.derive(n)
        finally:
            printed = self._core.printed()
            if printed:
                sys.stderr.write(printed)
        return self

    @property
    def steps(self):
        """The steps derived so far."""
        return self._core.steps

    @property
    def target_steps(self):
        """The steps the derivation runs to: ``steps=``, or the grammar's ``derive N;``."""
        return self._core.target_steps

    @property
    def done(self):
        """Whether the derivation is over (all steps run, or a hook said ``stop;``)."""
        return self._core.done

    @property
    def seed(self):
        """The seed in use: ``seed=``, the grammar's ``seed S;``, else 0."""
        return self._core.seed

    def __len__(self):
        return len(self._core)

    def modules(self):
        """The derived string as a list of :class:`Module` (name, parameters)."""
        return self._core.modules()

    def __str__(self):
        return self._core.text(False)

    def text(self, ids=False):
        """The string as ``plant derive`` prints it (``ids``: as ``plant derive --ids``)."""
        return self._core.text(bool(ids))

    def skeleton(self):
        """What the turtle drew, as numpy arrays (docs/skeleton.md): per point ``positions``,
        ``headings``, ``lefts``, ``ups`` (float64, (N, 3)), ``radii`` (float64, (N,)), ``colors``
        (float32, (N, 3)), ``ids`` (uint64, the module that drew it), ``axis`` (int32); per axis
        ``axis_parent`` (int32, -1 for the trunk) and ``axis_start`` (int64, axes + 1: each axis's
        points are ``axis_start[a]:axis_start[a + 1]``); per organ ``organ_transforms`` (float64,
        (M, 4, 4), row-major: ``T @ [x, y, z, 1]``), ``organ_colors``, ``organ_ids`` and
        ``organ_names``."""
        return Arrays("Skeleton", self._core.skeleton())

    def mesh(self, sides=8):
        """The meshed plant as one world-space triangle mesh with every placement drawn out (as
        ``.obj`` writes it; the environments' obstacles left out): ``vertices``, ``normals``
        (float32, (V, 3)), ``uvs`` (float32, (V, 2)), ``indices`` (uint32, (T, 3)); per triangle
        ``material`` (uint32, an index in ``colors``, float32 (K, 3) linear RGB, and ``textures``,
        a name or None) and ``group`` (int32: -1 for the tubes, k for the k-th placed organ, whose
        prototype is ``group_names[k]``); ``bounds`` (float32, (2, 3): min and max, as
        ``.mesh.txt``). ``sides``: vertices around each ring of a branch, as ``plant run --sides``."""
        return Arrays("Mesh", self._core.mesh(int(sides)))

    def save(self, path, *more, sides=8, size=(800, 800), layout="instanced", obstacles=True):
        """Writes the plant to every path, each in the format its extension names: any that
        ``plant run -o`` writes (``.glb .gltf .obj .ply .off .png .svg .txt .skel.json
        .mesh.txt``), all or nothing. ``layout``: how glTF places organs (``"instanced"``,
        ``"nodes"`` as ``--no-gpu-instancing``, ``"flatten"`` as ``--flatten``); ``size``: of PNG
        images; ``obstacles``: the environments' obstacles too. Raises :class:`ExportError`."""
        if layout not in _LAYOUTS:
            raise ValueError("layout must be one of %s, got %r" % (", ".join(_LAYOUTS), layout))
        paths = [os.fspath(p) for p in (path,) + more]
        width, height = size
        self._core.save(paths, int(sides), int(width), int(height), layout, bool(obstacles))

    def png(self, size=(400, 400), sides=8):
        """A shaded preview as PNG bytes, as ``plant run -o x.png`` draws it."""
        width, height = size
        return self._core.png(int(width), int(height), int(sides))

    def show(self, size=(400, 400)):
        """An :class:`Image` of the plant, shown inline in Jupyter."""
        return Image(self.png(size))

    def __repr__(self):
        return "<plant.Plant %s: step %d of %d, %d modules>" % (
            self.name, self.steps, self.target_steps, len(self))


def show(plant_or_source, size=(400, 400), **compile_args):
    """An inline PNG (:class:`Image`) of a plant; a grammar (a path or text, with ``compile``'s
    arguments) is compiled and derived first. In Jupyter, ``plant.show("fig12c.plant")``."""
    if not isinstance(plant_or_source, Plant):
        plant_or_source = compile(plant_or_source, **compile_args).derive()
    return plant_or_source.show(size)
