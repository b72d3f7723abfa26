"""Every public name has a numpydoc docstring, and every public function and
method full type hints that resolve."""
import inspect
import re
import typing
import unittest

import liepoisson as lp

SECTION = re.compile(r"^\s*(Parameters|Returns|Raises|Attributes|Notes|Examples)\n\s*-{3,}$", re.M)


def public_members(cls):
    for name, member in vars(cls).items():
        if name.startswith("_") and name not in ("__init__",):
            continue
        yield "%s.%s" % (cls.__name__, name), member


def documented_callables():
    for name in lp.__all__:
        obj = getattr(lp, name)
        if inspect.isclass(obj) and obj.__module__ == lp.__name__:
            yield name, obj
            for qual, member in public_members(obj):
                if isinstance(member, property):
                    yield qual, member.fget
                elif isinstance(member, (staticmethod, classmethod)):
                    yield qual, member.__func__
                elif inspect.isfunction(member):
                    yield qual, member
        elif inspect.isfunction(obj):
            yield name, obj


class TestDocs(unittest.TestCase):
    def test_every_public_name_is_documented(self):
        self.assertTrue(lp.__doc__)
        missing = [name for name, obj in documented_callables()
                   if not (obj.__doc__ or "").strip() and not name.endswith("__init__")]
        self.assertEqual(missing, [])
        for name in lp.__all__:
            if not callable(getattr(lp, name)):
                self.assertIn(name, lp.__doc__ + " ".join(lp.STATUS), "module attribute %s undescribed" % name)

    def test_parameters_sections_name_every_parameter(self):
        wrong = []
        for name, fn in documented_callables():
            if name.endswith(".__init__"):
                continue  # numpydoc: the class docstring documents the constructor
            if inspect.isclass(fn):
                if "__init__" not in vars(fn):
                    continue  # inherited: documented where defined
                doc, fn = fn.__doc__ or "", vars(fn)["__init__"]
            else:
                doc = fn.__doc__ or ""
            params = [p for p in inspect.signature(fn).parameters if p not in ("self", "cls") and not p.startswith("_")]
            if not params:
                continue
            sections = SECTION.findall(doc)
            if "Parameters" not in sections:
                wrong.append("%s: no Parameters section" % name)
                continue
            for p in params:
                # "name : type", or several names sharing one entry ("I1, I2, I3 : float")
                if not re.search(r"^\s*(?:\w+,\s*)*%s(?:,\s*\w+)*\s*:" % re.escape(p), doc, re.M):
                    wrong.append("%s: parameter %s undocumented" % (name, p))
        self.assertEqual(wrong, [])

    def test_type_hints_resolve_and_cover_every_signature(self):
        wrong = []
        for name, fn in documented_callables():
            if inspect.isclass(fn):
                continue
            try:
                hints = typing.get_type_hints(fn)
            except Exception as e:  # noqa: B902 - report, do not stop
                wrong.append("%s: %s" % (name, e))
                continue
            for p in inspect.signature(fn).parameters:
                if p not in ("self", "cls") and p not in hints:
                    wrong.append("%s: %s unannotated" % (name, p))
            if "return" not in hints:
                wrong.append("%s: no return annotation" % name)
        self.assertEqual(wrong, [])

    def test_py_typed_is_shipped(self):
        import os
        self.assertTrue(os.path.isfile(os.path.join(os.path.dirname(lp.__file__), "py.typed")))


if __name__ == "__main__":
    unittest.main()
