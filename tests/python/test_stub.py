"""The type stub omnical/_omnical.pyi against the module it describes: every public class,
function, method and property of the extension is in the stub with the same parameter
names (from pybind11's signature lines), and the stub names nothing the module lacks.
Every public object has a docstring (help() shows it)."""
import ast
import inspect
import pathlib
import re

import omnical
from omnical import _omnical

STUB = pathlib.Path(omnical.__file__).with_name("_omnical.pyi")
SIGNATURE = re.compile(r"^(\w+)\((.*)\) ->", re.M)


def stub_tree():
    tree = ast.parse(STUB.read_text())
    names, members = {}, {}
    for node in tree.body:
        if isinstance(node, ast.ClassDef):
            names[node.name] = node
            members[node.name] = {item.name: item for item in node.body if isinstance(item, ast.FunctionDef)}
        elif isinstance(node, ast.FunctionDef):
            names[node.name] = node
        elif isinstance(node, ast.AnnAssign):
            names[node.target.id] = node
        elif isinstance(node, ast.Assign):
            names[node.targets[0].id] = node
    return names, members


def runtime_parameters(function):
    """Parameter names of every overload, from pybind11's signature lines."""
    found = []
    for match in SIGNATURE.finditer(function.__doc__ or ""):
        text = match.group(2)
        depth, current, parts = 0, "", []
        for char in text:
            depth += char in "([{"
            depth -= char in ")]}"
            if char == "," and depth == 0:
                parts.append(current)
                current = ""
            else:
                current += char
        parts.append(current)
        found.append([p.split(":")[0].split("=")[0].strip() for p in parts if p.strip() not in ("", "*")])
    return found


def matches(stub, overloads):
    """The stub's parameters are one overload's; a **kwargs overload (forwarding to another
    function) must be a prefix of the stub, which spells the forwarded keywords out."""
    for names in overloads:
        if names and names[-1].startswith("**"):
            if stub[:len(names) - 1] == names[:-1]:
                return True
        elif stub == names:
            return True
    return False


def stub_parameters(node):
    arguments = node.args
    return [a.arg for a in arguments.posonlyargs + arguments.args + arguments.kwonlyargs]


def public(names):
    return {n for n in names if not n.startswith("_")}


def test_the_stub_names_exactly_the_modules_public_objects():
    names, _ = stub_tree()
    runtime = public(dir(_omnical)) - {"PathLike", "ArrayLike", "Progress"}
    stubbed = public(names) - {"PathLike", "ArrayLike", "Progress"}
    assert runtime - stubbed == set(), "in the module, not in the stub"
    assert stubbed - runtime == set(), "in the stub, not in the module"


def test_functions_and_methods_have_the_stubs_parameters_and_docstrings():
    names, members = stub_tree()
    checked = 0
    for name in public(dir(_omnical)):
        value = getattr(_omnical, name)
        assert (value.__doc__ or "").strip(), f"{name}: no docstring"
        if inspect.isclass(value):
            if issubclass(value, BaseException):
                continue
            stub_members = members[name]
            runtime_members = {m for m in vars(value) if not m.startswith("_")}
            assert runtime_members == public(stub_members), name
            for member in runtime_members:
                attribute = inspect.getattr_static(value, member)
                function = getattr(value, member)
                assert (function.__doc__ or "").strip(), f"{name}.{member}: no docstring"
                if isinstance(attribute, property):
                    assert any(isinstance(d, ast.Name) and d.id == "property" for d in stub_members[member].decorator_list), \
                        f"{name}.{member} is a property"
                    continue
                expected = stub_parameters(stub_members[member])
                if expected and expected[0] == "self":
                    expected = expected[1:]
                overloads = runtime_parameters(function)
                assert overloads, f"{name}.{member}: no signature line"
                assert matches(expected, [o[1:] if o and o[0] == "self" else o for o in overloads]), \
                    f"{name}.{member}: stub {expected}, module {overloads}"
                checked += 1
        elif callable(value):
            assert matches(stub_parameters(names[name]), runtime_parameters(value)), \
                f"{name}: stub {stub_parameters(names[name])}, module {runtime_parameters(value)}"
            checked += 1
    assert checked >= 10


def test_the_package_documents_its_own_additions():
    assert omnical.__doc__ and omnical.ProjectionStatus.__doc__ and omnical.status_name.__doc__
    assert STUB.with_name("py.typed").exists()
