"""The type stubs describe the module as it is: every name, every parameter."""

import ast
import inspect

from conftest import ROOT

from dlo_planner import _dlo

STUB = ROOT / "python" / "dlo_planner" / "_dlo.pyi"


def stub_functions():
    tree = ast.parse(STUB.read_text())
    for node in tree.body:
        if isinstance(node, ast.FunctionDef):
            yield node.name, None, node
        elif isinstance(node, ast.ClassDef):
            for item in node.body:
                if isinstance(item, ast.FunctionDef):
                    yield item.name, node.name, item


def test_every_stub_names_the_runtime_parameters():
    checked = 0
    for name, owner, node in stub_functions():
        if any(isinstance(d, ast.Name) and d.id == "property" for d in node.decorator_list):
            target = getattr(_dlo, owner)
            assert isinstance(getattr(target, name), property) or hasattr(target, name), (owner, name)
            continue
        obj = getattr(getattr(_dlo, owner), name) if owner else getattr(_dlo, name)
        if owner and name == "__init__":
            obj = getattr(_dlo, owner)
        stub = [a.arg for a in node.args.args if a.arg != "self"]
        runtime = [p for p in inspect.signature(obj).parameters if p != "self"]
        assert stub == runtime, (owner, name, stub, runtime)
        checked += 1
    assert checked >= 20


def test_every_public_runtime_name_has_a_stub():
    tree = ast.parse(STUB.read_text())
    stubbed = {n.name for n in tree.body if isinstance(n, (ast.FunctionDef, ast.ClassDef))}
    stubbed |= {t.id for n in tree.body if isinstance(n, ast.AnnAssign) for t in [n.target]}
    public = {n for n in dir(_dlo) if not n.startswith("_")} | {"__version__"}
    assert public <= stubbed | {"__version__"}, public - stubbed
