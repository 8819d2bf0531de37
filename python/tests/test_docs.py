"""Everything public has a docstring, and the type stubs name everything
the native module has."""

import ast
import inspect
import pathlib

import tmclsim
from tmclsim import _tmclsim

STUB = pathlib.Path(_tmclsim.__file__).with_name("_tmclsim.pyi")


def public(obj):
    return [n for n in dir(obj) if not n.startswith("_")]


def test_everything_public_has_a_docstring():
    missing = []
    for name in tmclsim.__all__:
        obj = getattr(tmclsim, name)
        if not (obj.__doc__ or "").strip():
            missing.append(name)
        if inspect.isclass(obj) and not issubclass(obj, BaseException):
            for member in public(obj):
                attribute = getattr(obj, member)
                if not (getattr(attribute, "__doc__", None) or "").strip():
                    missing.append(f"{name}.{member}")
    assert missing == []


def test_the_stubs_cover_the_native_module():
    tree = ast.parse(STUB.read_text())
    stubbed = {}
    for node in tree.body:
        if isinstance(node, ast.ClassDef):
            stubbed[node.name] = {n.name for n in node.body if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef))}
        elif isinstance(node, ast.FunctionDef):
            stubbed[node.name] = set()
    for name in public(_tmclsim):
        assert name in stubbed, f"{name} has no stub"
        obj = getattr(_tmclsim, name)
        if inspect.isclass(obj):
            for member in public(obj):
                assert member in stubbed[name], f"{name}.{member} has no stub"
    assert (STUB.parent / "py.typed").exists()


def test_the_native_signatures_are_visible():
    assert str(inspect.signature(tmclsim.Module.send)) == "(self, /, command, type=None, motor=None, value=None)"
    assert "profile" in str(inspect.signature(tmclsim.assemble))
