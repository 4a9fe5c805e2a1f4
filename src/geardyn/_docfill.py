"""Shared docstring entries: a parameter documented the same way in many places is written once.

An entry is numpydoc text as it stands in a ``Parameters``, ``Attributes`` or ``Returns`` section:
``name : type``, then its description indented by four spaces.  A docstring names shared entries by
a line holding only ``{{name}}`` (or ``{{name, other}}`` for several in a row); the decorator
:func:`fill` replaces that line by the entries, indented like the line, when the function or class
is defined, so ``help()``, :func:`inspect.getdoc` and the documentation tests read the finished
docstring.  A placeholder with no entry, or an entry given to :func:`fill` and not used, is an
error at import, never a silent gap.  Where the shared entries are all of a function's parameters,
:func:`parameters` appends the whole ``Parameters`` section instead.

The entries used across modules are the constants below; a module keeps its own as constants next to
the functions that share them.
"""

from __future__ import annotations

import inspect
import re
from collections.abc import Callable
from typing import TypeVar

__all__ = [
    "attributes",
    "fill",
    "parameters",
    "result_of",
    "RESULT",
    "SUMMARY",
]

T = TypeVar("T")

_SECTION = re.compile(r"^(Returns|Yields|Raises|Warns|Attributes|See Also|Notes|References|Examples)\n-{3,}$", re.M)

_PLACEHOLDER = re.compile(r"^(?P<indent>[ \t]*)\{\{(?P<names>\w+(?:, *\w+)*)\}\}[ \t]*$", re.M)

#: ``ds`` of a function of any geardyn result.
RESULT = """ds : xarray.Dataset
    A geardyn result."""
#: ``s`` of a function printing or writing a command's summary.
SUMMARY = """s : dict
    The command's JSON summary."""


def fill(*entries: str) -> Callable[[T], T]:
    """Decorator: replace every ``{{name}}`` line of the docstring by the entry of parameter ``name``.

    Parameters
    ----------
    *entries : str
        The entries, each numpydoc text without indentation: its first line ``name : type``, the
        following lines indented by four spaces.

    Returns
    -------
    callable
        The decorator; it returns the function or class it decorates with its docstring filled in.

    Raises
    ------
    KeyError
        If the docstring names a parameter that no entry documents.
    ValueError
        If an entry is not used by the docstring.
    """
    by_name = {entry.split(" : ", 1)[0].strip(): entry for entry in entries}

    def deco(obj: T) -> T:
        used: set[str] = set()

        def expand(match: re.Match) -> str:
            names = [n.strip() for n in match["names"].split(",")]
            used.update(names)
            text = "\n".join(by_name[n] for n in names)
            return "\n".join(match["indent"] + line if line else line for line in text.splitlines())

        obj.__doc__ = _PLACEHOLDER.sub(expand, obj.__doc__ or "")
        unused = set(by_name) - used
        if unused:
            raise ValueError(f"{obj.__qualname__}: entries not used by the docstring: {sorted(unused)}")
        return obj

    return deco


def _add_section(obj: T, title: str, entries: tuple[str, ...] | list[str]) -> T:
    """Give ``obj``'s docstring the section ``title`` before its first section (or at its end)."""
    doc = inspect.cleandoc(obj.__doc__ or "")
    if re.search(rf"^{title}\n-{{3,}}$", doc, re.M):
        raise ValueError(f"{obj.__qualname__}: the docstring has its own {title} section")
    section = "\n".join([title, "-" * len(title), *entries])
    first = _SECTION.search(doc)
    at = first.start() if first else len(doc)
    head, tail = doc[:at].rstrip(), doc[at:]
    obj.__doc__ = f"{head}\n\n{section}\n" + (f"\n{tail}\n" if tail else "")
    return obj


def parameters(*entries: str) -> Callable[[T], T]:
    """Decorator: give a docstring that has none a ``Parameters`` section made of ``entries``.

    The section goes before the docstring's first section (``Returns``, ``Raises``, …), or at its
    end if it has none.

    Parameters
    ----------
    *entries : str
        The entries in the order of the signature, each as for :func:`fill`.

    Returns
    -------
    callable
        The decorator; it returns the function it decorates with the section added.

    Raises
    ------
    ValueError
        If the docstring already has a ``Parameters`` section.
    """
    return lambda obj: _add_section(obj, "Parameters", entries)


_FIELD = re.compile(r"^(?P<name>[A-Za-z_]\w*)\s*:\s*(?P<type>[^=]+?)\s*(=.*)?$")


def attributes(cls: T) -> T:
    """Class decorator: the ``Attributes`` section of a data class from the ``#:`` comments of its fields.

    A field is documented by the ``#:`` lines right above it; the fields that follow it with no
    blank line, comment or other statement between share its entry (``a, b : type``).  The type of
    an entry is the fields' annotation as written (their annotations in order where they differ).
    Decorate the class before :func:`dataclasses.dataclass` sees it (``@attributes`` below
    ``@dataclass``).

    Parameters
    ----------
    cls : type
        The class; without readable source (:func:`inspect.getsourcelines`) it is returned unchanged.

    Returns
    -------
    type
        ``cls`` with the section added to its docstring.

    Raises
    ------
    ValueError
        If the docstring already has an ``Attributes`` section.
    """
    try:
        lines = inspect.getsourcelines(cls)[0]
    except (OSError, TypeError):  # no source (a frozen build): the class keeps the docstring it has
        return cls
    start = next(i for i, line in enumerate(lines) if line.lstrip().startswith("class "))
    body = [line.rstrip("\n") for line in lines[start + 1 :]]
    indent = min(len(line) - len(line.lstrip()) for line in body if line.strip())
    entries: list[list] = []  # [names, type, comment lines]
    comment: list[str] = []
    grouping = False
    for line in body:
        if not line.strip():
            grouping = False
            continue
        if len(line) - len(line.lstrip()) != indent:
            continue  # inside the docstring or a method
        text = line.strip()
        if text.startswith("#:"):
            comment.append(text[2:].strip())
            continue
        field = _FIELD.match(text)
        if field and comment:
            entries.append([[field["name"]], [field["type"]], comment])
            comment, grouping = [], True
        elif field and grouping:
            entries[-1][0].append(field["name"])
            entries[-1][1].append(field["type"])
        elif text.startswith(("def ", "@", "async def ")):
            break
        else:
            grouping = False
    docs = [
        f"{', '.join(names)} : {kinds[0] if len(set(kinds)) == 1 else ', '.join(kinds)}\n"
        + "\n".join("    " + c for c in text)
        for names, kinds, text in entries
    ]
    return _add_section(cls, "Attributes", docs)


def result_of(producer: str) -> str:
    """The entry of a ``ds`` parameter holding the Dataset that the function ``producer`` returns.

    Parameters
    ----------
    producer : str
        The function's name, as the reference ``:func:`producer``` renders it.

    Returns
    -------
    str
        ``ds : xarray.Dataset``, described as ``A :func:`producer` result.``
    """
    return f"ds : xarray.Dataset\n    A :func:`{producer}` result."
