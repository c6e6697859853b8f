"""The stubs name what the module has, and the module what the stubs name."""

import ast
import inspect
import pathlib

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
    for name in ("sample_surface", "blue_noise", "tetrahedralize", "load_tets"):
        doc = getattr(trilux, name).__doc__
        assert "float64" in doc and "int64" in doc, name
