"""The package's surface: the type stubs (`_sahara.pyi`, `py.typed`) are
installed and name every function, class, method and parameter of the
native module as it is, and every public object has a docstring."""

import ast
import inspect
import pathlib

import pytest

import sahara
import sahara._sahara as native
import sahara.trimesh

PACKAGE = pathlib.Path(sahara.__file__).parent


def stub():
    return ast.parse((PACKAGE / "_sahara.pyi").read_text())


def parameters(fn: ast.FunctionDef):
    a = fn.args
    names = [p.arg for p in a.posonlyargs + a.args + a.kwonlyargs]
    return [n for n in names if n != "self"]


def test_the_stubs_and_the_typed_marker_are_installed():
    assert (PACKAGE / "py.typed").is_file()
    assert (PACKAGE / "_sahara.pyi").is_file()


def test_the_stubs_name_every_public_object_of_the_native_module():
    names = {n.name for n in stub().body if isinstance(n, (ast.FunctionDef, ast.ClassDef))}
    public = {n for n in dir(native) if not n.startswith("_")}
    assert public <= names, public - names


def runtime_parameters(obj):
    """The parameters of `obj`; its `**settings` are the render settings'
    keywords, which the stub lists one by one for editors."""
    names = []
    for p in inspect.signature(obj).parameters.values():
        if p.kind is p.VAR_KEYWORD:
            names += native.names()["setting"]
        elif p.name != "self":
            names.append(p.name)
    return names


def test_the_stubs_signatures_are_the_native_modules():
    checked = 0
    for node in stub().body:
        if isinstance(node, ast.FunctionDef):
            assert parameters(node) == runtime_parameters(getattr(native, node.name)), node.name
            checked += 1
        elif isinstance(node, ast.ClassDef) and node.name == "RayScene":
            cls = getattr(native, node.name)
            for fn in node.body:
                if isinstance(fn, ast.FunctionDef) and not any(
                    isinstance(d, ast.Name) and d.id == "property" for d in fn.decorator_list
                ):
                    target = cls if fn.name == "__init__" else getattr(cls, fn.name)
                    assert parameters(fn) == runtime_parameters(target), f"RayScene.{fn.name}"
                    checked += 1
    assert checked >= 14


@pytest.mark.parametrize(
    "obj",
    [getattr(sahara, n) for n in sahara.__all__ if n != "__version__"]
    + [getattr(native.RayScene, n) for n in dir(native.RayScene) if not n.startswith("_")]
    + [sahara.trimesh, sahara.trimesh.RayMeshIntersector]
    + [getattr(sahara.trimesh.RayMeshIntersector, n) for n in dir(sahara.trimesh.RayMeshIntersector)
       if not n.startswith("_")],
    ids=repr,
)
def test_every_public_object_has_a_docstring(obj):
    assert (obj.__doc__ or "").strip()
