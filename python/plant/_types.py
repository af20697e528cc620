"""Plain values the module returns (docs/api.md, Python)."""

from typing import NamedTuple, Tuple


class Module(NamedTuple):
    """One module of the derived string: its name and its parameters (a vector parameter is
    three numbers in a row, as plant prints it)."""

    name: str
    params: Tuple[float, ...]

    def __str__(self):
        if not self.params:
            return self.name
        return "%s(%s)" % (self.name, ",".join(_number(p) for p in self.params))


def _number(x):
    return str(int(x)) if float(x).is_integer() and abs(x) < 1e15 else repr(x)


class Arrays:
    """Named numpy arrays (and lists of names): ``skeleton()`` and ``mesh()`` return one."""

    def __init__(self, kind, fields):
        self._kind = kind
        self._fields = list(fields)
        for name, value in fields.items():
            setattr(self, name, value)

    def keys(self):
        return list(self._fields)

    def __getitem__(self, name):
        if name not in self._fields:
            raise KeyError(name)
        return getattr(self, name)

    def __repr__(self):
        parts = []
        for name in self._fields:
            value = getattr(self, name)
            shape = getattr(value, "shape", None)
            if shape is not None:
                parts.append("%s=%s[%s]" % (name, value.dtype, ",".join(str(n) for n in shape)))
            else:
                parts.append("%s=[%d names]" % (name, len(value)))
        return "%s(%s)" % (self._kind, ", ".join(parts))


class Image:
    """A PNG image: shown inline by Jupyter and IPython (``_repr_png_``), ``data`` holds its bytes."""

    def __init__(self, data: bytes):
        self.data = data

    def _repr_png_(self):
        return self.data

    def save(self, path):
        with open(path, "wb") as f:
            f.write(self.data)

    def __repr__(self):
        return "<plant.Image: %d bytes of PNG>" % len(self.data)
