# The Python module: compiling, deriving, the string, params and seeds, errors, file access
# (docs/api.md, Python).
import os
import pathlib
import subprocess
import threading
import time

import pytest

import plant

STOCHASTIC = """
module A(x);
derive 6;
axiom: A(0);
rules {
  A(x) -> A(x + 1) [B(uniform(0, 1))] A(x + 2) : 1;
  A(x) -> A(x * 2) : 1;
}
"""


def test_compile_from_source_text():
    p = plant.compile("module A(x);\nparam n = 2;\nderive 3;\naxiom: A(n);\nrules { A(x) -> A(x + 1) F(x); }\n")
    assert p.steps == 0 and p.target_steps == 3 and not p.done
    assert str(p) == "A(2)"
    assert p.derive(1) is p and p.steps == 1
    assert str(p) == "A(3)F(2)"
    p.derive()
    assert p.steps == 3 and p.done
    assert str(p) == "A(5)F(4)F(3)F(2)"
    mods = p.modules()
    assert len(mods) == len(p) == 4
    assert mods[0] == plant.Module("A", (5.0,)) and mods[0].name == "A" and mods[0].params == (5.0,)
    assert [str(m) for m in mods] == ["A(5)", "F(4)", "F(3)", "F(2)"]
    p.derive(5)  # the derivation is over: nothing more
    assert p.steps == 3


def test_compile_from_path(rose, plant_exe):
    for source in (rose, str(rose)):
        p = plant.compile(source, seed=3).derive()
        assert p.name == str(rose) and p.seed == 3 and p.done
    # the string is the one plant derive prints
    out = subprocess.run([plant_exe, "derive", str(rose), "--seed", "3"], capture_output=True, text=True, check=True)
    assert str(p) + "\n" == out.stdout
    ids = subprocess.run([plant_exe, "derive", str(rose), "--seed", "3", "--ids"], capture_output=True, text=True,
                         check=True)
    assert p.text(ids=True) + "\n" == ids.stdout


def test_params_and_steps():
    src = "module A(x);\nparam n = 2;\nparam k = 1;\nderive 1;\naxiom: A(n);\nrules { A(x) -> A(x * k); }\n"
    assert str(plant.compile(src).derive()) == "A(2)"
    assert str(plant.compile(src, params={"n": 5, "k": 0.5}).derive()) == "A(2.5)"
    assert str(plant.compile(src, params={"n": "3 * 4"}).derive()) == "A(12)"  # an expression, as -D
    assert str(plant.compile(src, steps=3, params={"k": 2}).derive()) == "A(16)"
    with pytest.raises(TypeError):
        plant.compile(src, params={"n": [1]})
    with pytest.raises(ValueError):
        plant.compile(src, params={"n": float("nan")})
    with pytest.raises(plant.CompileError):
        plant.compile(src, params={"n": "1 +"})


def test_seed():
    a = [str(plant.compile(STOCHASTIC, seed=s).derive()) for s in (1, 1, 2)]
    assert a[0] == a[1]
    assert a[0] != a[2]
    # the result never depends on the thread count
    assert str(plant.compile(STOCHASTIC, seed=1, threads=2).derive()) == a[0]
    with pytest.raises(ValueError):
        plant.compile(STOCHASTIC, seed=-1)


def test_compile_error_carries_diagnostics(tmp_path):
    bad = tmp_path / "bad.plant"
    bad.write_text("axiom: F;\nrules { F -> F(1 +; }\n")
    with pytest.raises(plant.CompileError) as info:
        plant.compile(bad)
    e = info.value
    assert isinstance(e, plant.Error)
    assert f"{bad}:2:" in str(e)
    assert e.file == str(bad) and e.line == 2 and e.column > 1
    assert f"{bad}:2:{e.column}: error:" in str(e)
    assert "^" in str(e)  # the caret under the place
    d = e.diagnostics[0]
    assert d.severity == "error" and d.message and d.rendered.startswith(f"{bad}:2:{e.column}")
    with pytest.raises(plant.CompileError, match="cannot read"):
        plant.compile(tmp_path / "missing.plant")


def test_runtime_error_names_the_place():
    src = "module A(x);\nderive 3;\naxiom: A(1);\nrules { A(x) -> A(x - 1) F(1 / x); }\n"
    p = plant.compile(src, name="div.plant")
    with pytest.raises(plant.DeriveError) as info:
        p.derive()
    assert "div.plant:4:" in str(info.value) and "division by zero" in str(info.value)
    assert info.value.line == 4


def test_file_access(tmp_path):
    (tmp_path / "lib").mkdir()
    (tmp_path / "lib" / "extra.plant").write_text("module E;\n")
    (tmp_path / "g").mkdir()
    g = tmp_path / "g" / "main.plant"
    g.write_text('import "../lib/extra.plant";\naxiom: E;\n')
    with pytest.raises(plant.CompileError) as info:
        plant.compile(g)
    assert "outside the folders" in str(info.value) and f"{g}:1:" in str(info.value)
    assert str(plant.compile(g, allow_read=[tmp_path / "lib"])) == "E"


def test_hook_print_goes_to_stderr(capsys):
    plant.compile('derive 1;\naxiom: F;\non end { print("done"); }\n').derive()
    assert "done" in capsys.readouterr().err


def test_derive_releases_the_gil():
    # 2^22 modules, a few tenths of a second: while another thread derives, this one keeps
    # running. Holding the GIL, the longest pause between two of its loops would be the whole
    # derivation (a call into C++ that keeps the GIL lets no other thread run Python).
    p = plant.compile("derive 22;\naxiom: F;\nrules { F -> F F; }\n")
    worker = threading.Thread(target=p.derive)
    start = last = time.perf_counter()
    longest = 0.0
    worker.start()
    while worker.is_alive():
        now = time.perf_counter()
        longest = max(longest, now - last)
        last = now
    worker.join()
    took = time.perf_counter() - start
    assert len(p) == 2**22
    assert longest < took / 2, (longest, took)


def test_installed_package():
    prefix = os.environ.get("PLANT_EXPECT_PREFIX")
    if not prefix:
        pytest.skip("not testing an install")
    assert pathlib.Path(plant.__file__).resolve().is_relative_to(pathlib.Path(prefix).resolve())
    assert pathlib.Path(plant.STDLIB) == pathlib.Path(prefix) / "share" / "plant" / "stdlib"
