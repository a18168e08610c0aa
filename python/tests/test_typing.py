# SPDX-License-Identifier: MIT
"""Type hints on the public API (issue 52): every public function and method
of rcal annotates each parameter and its return, the annotations resolve
(typing.get_type_hints), and the package is marked typed (PEP 561)."""
import inspect
import os
import typing

import rcal


def _public_callables():
    out = []
    for name in rcal.__all__:
        obj = getattr(rcal, name)
        if inspect.isfunction(obj):
            out.append(("rcal." + name, obj))
        elif inspect.isclass(obj) and obj.__module__ == "rcal":
            for mname, m in vars(obj).items():
                if mname.startswith("_"):
                    continue
                f = m.fget if isinstance(m, property) else getattr(m, "__func__", m)
                if inspect.isfunction(f):
                    out.append(("rcal.%s.%s" % (name, mname), f))
    return out


def test_every_public_function_is_annotated():
    funcs = _public_callables()
    names = [n for n, _ in funcs]
    for expected in ("rcal.calibrate", "rcal.diagnose", "rcal.compensate", "rcal.evaluate", "rcal.export",
                     "rcal.report", "rcal.Model.fk", "rcal.Result.write"):
        assert expected in names
    missing = []
    for n, f in funcs:
        sig = inspect.signature(f)
        for p in sig.parameters.values():
            if p.name in ("self", "cls"):
                continue
            if p.annotation is inspect.Parameter.empty:
                missing.append("%s(%s)" % (n, p.name))
        if sig.return_annotation is inspect.Signature.empty:
            missing.append(n + " -> ?")
        typing.get_type_hints(f, vars(rcal))  # the annotations resolve
    assert missing == []


def test_package_is_marked_typed():
    assert os.path.isfile(os.path.join(os.path.dirname(rcal.__file__), "py.typed"))
