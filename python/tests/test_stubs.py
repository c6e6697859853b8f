"""The stubs name what the module has, and the module what the stubs name."""

import ast
import inspect
import itertools
import pathlib

import numpy as np

import trilux

STUB = pathlib.Path(trilux.__file__).with_name("__init__.pyi")


def stub_names():
    tree = ast.parse(STUB.read_text())
    top, members = set(), {}
    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            top.add(node.name)
        if isinstance(node, ast.ClassDef):
            members[node.name] = {
                n.name for n in node.body if isinstance(n, ast.FunctionDef) and not n.name.startswith("__")
            } | ({"__init__"} if any(isinstance(n, ast.FunctionDef) and n.name == "__init__" for n in node.body) else set())
        if isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name) and node.target.id == "__version__":
            top.add("__version__")
    return top, members


def test_stub_and_module_agree():
    top, members = stub_names()
    assert top == set(trilux.__all__)
    for name, methods in members.items():
        cls = getattr(trilux, name)
        runtime = {n for n in dir(cls) if not n.startswith("__")}
        if issubclass(cls, BaseException):
            continue
        assert methods - {"__init__"} == runtime, name


def test_signatures_match_the_stubs():
    tree = ast.parse(STUB.read_text())
    for node in tree.body:
        if isinstance(node, ast.FunctionDef):
            params = [a.arg for a in node.args.posonlyargs + node.args.args + node.args.kwonlyargs]
            runtime = list(inspect.signature(getattr(trilux, node.name)).parameters)
            assert params == runtime, node.name


def test_docstrings_give_shapes():
    for name in ("sample_surface", "blue_noise", "scatter", "tetrahedralize", "load_tets"):
        doc = getattr(trilux, name).__doc__
        assert "float64" in doc and "int64" in doc, name


def overloads():
    """name -> [(flag annotations {flag: "True" | "False" | "bool"}, the return
    annotation's source)] of each stub function with `return_*` flags, in
    the stub's order."""
    out = {}
    for node in ast.parse(STUB.read_text()).body:
        if not isinstance(node, ast.FunctionDef):
            continue
        flags = {}
        for a in node.args.kwonlyargs:
            if a.arg.startswith("return_"):
                text = ast.unparse(a.annotation)
                flags[a.arg] = {"Literal[True]": "True", "Literal[False]": "False"}.get(text, text)
        if flags:
            out.setdefault(node.name, []).append((flags, ast.unparse(node.returns)))
    return out


def tuple_length(annotation):
    """How many arrays a `Tuple[...]` return annotation names."""
    assert annotation.startswith("Tuple[") and annotation.endswith("]"), annotation
    return len(ast.parse(annotation, mode="eval").body.slice.elts)


def test_every_combination_of_return_flags_has_a_literal_overload_and_a_bool_fallback():
    found = overloads()
    assert set(found) == {"sample_surface", "blue_noise", "scatter", "tetrahedralize", "load_tets"}, set(found)
    for name, variants in found.items():
        flags = list(variants[0][0])
        literal = [v for v in variants if all(v[0][f] in ("True", "False") for f in flags)]
        combos = sorted(tuple(v[0][f] == "True" for f in flags) for v in literal)
        assert combos == sorted(itertools.product([False, True], repeat=len(flags))), name
        # The plain-bool fallback comes last (mypy picks the first match).
        fallback = variants[-1][0]
        assert all(fallback[f] == "bool" for f in flags), name
        assert len(variants) == len(literal) + 1, name
        for v, ret in literal:
            extra = sum(v[f] == "True" for f in flags)
            assert tuple_length(ret) == 2 + extra, (name, v, ret)


def test_the_literal_overloads_say_how_many_arrays_come_back(tmp_path):
    from conftest import grid

    v, f, _ = grid(3)
    octahedron = (np.array([[1.0, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]]),
                  [[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]])
    nodes, tets = trilux.tetrahedralize(octahedron, spacing=0.5)
    trilux.save_tets(tmp_path / "o.mesh", nodes, tets)
    calls = {
        "sample_surface": lambda **flags: trilux.sample_surface((v, f), 5, seed=1, **flags),
        "blue_noise": lambda **flags: trilux.blue_noise((v, f), 5, seed=1, **flags),
        "scatter": lambda **flags: trilux.scatter((v, f), 50.0, seed=1, **flags),
        "tetrahedralize": lambda **flags: trilux.tetrahedralize(octahedron, spacing=0.5, **flags),
        "load_tets": lambda **flags: trilux.load_tets(tmp_path / "o.mesh", **flags),
    }
    for name, variants in overloads().items():
        for flags, ret in variants[:-1]:
            got = calls[name](**{k: value == "True" for k, value in flags.items()})
            assert isinstance(got, tuple) and len(got) == tuple_length(ret), (name, flags, ret)
