"""The type stubs (mecano/__init__.pyi) against the module: the same public names, the
same kinds, the same parameters."""

import ast
import inspect
import pathlib

import mecano

STUB = pathlib.Path(mecano.__file__).with_name("__init__.pyi")


def stub_tree():
    return ast.parse(STUB.read_text())


def test_stub_and_marker_ship_with_the_package():
    assert STUB.exists()
    assert pathlib.Path(mecano.__file__).with_name("py.typed").exists()


def test_every_public_name_is_in_the_stub_and_back():
    tree = stub_tree()
    names = {
        n.name
        for n in tree.body
        if isinstance(n, (ast.FunctionDef, ast.ClassDef))
    } | {
        t.id
        for n in tree.body
        if isinstance(n, ast.AnnAssign)
        for t in [n.target]
        if isinstance(t, ast.Name)
    }
    public = set(mecano.__all__)
    assert public - names == set(), f"missing in the stub: {public - names}"
    extra = {n for n in names - public if not n.startswith("_")} - {"PathLike"}
    assert extra == set(), f"in the stub but not exported: {extra}"


def _params(fn):
    return [
        p.name
        for p in inspect.signature(fn).parameters.values()
        if p.name not in ("self", "cls")
    ]


def _stub_params(node):
    a = node.args
    ps = [x.arg for x in a.posonlyargs + a.args + a.kwonlyargs]
    if a.vararg:
        ps.append(a.vararg.arg)
    if a.kwarg:
        ps.append(a.kwarg.arg)
    return [p for p in ps if p not in ("self", "cls")]


def test_signatures_match():
    for node in stub_tree().body:
        if isinstance(node, ast.FunctionDef) and not node.name.startswith("_"):
            assert _params(getattr(mecano, node.name)) == _stub_params(node), node.name
        if isinstance(node, ast.ClassDef):
            cls = getattr(mecano, node.name)
            for item in node.body:
                if isinstance(item, ast.FunctionDef) and (
                    not item.name.startswith("_") or item.name == "__init__"
                ):
                    member = getattr(cls, item.name, None)
                    assert member is not None, f"{node.name}.{item.name} missing"
                    if any(
                        isinstance(d, ast.Name) and d.id == "property"
                        for d in item.decorator_list
                    ):
                        continue
                    try:
                        sig = _params(member)
                    except (TypeError, ValueError):
                        continue  # a builtin without a text signature
                    if item.name == "__init__":
                        continue
                    assert sig == _stub_params(item), f"{node.name}.{item.name}"
