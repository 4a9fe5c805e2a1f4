"""The shared docstring entries of geardyn._docfill."""

from __future__ import annotations

import inspect

import pytest

from geardyn._docfill import fill, parameters

X = "x : float\n    The abscissa."
Y = "y : float\n    The ordinate."


def test_fill_replaces_a_placeholder_line_with_the_entries_indented_like_it():
    @fill(X, Y)
    def f(x, y, z):
        """Do.

        Parameters
        ----------
        {{x, y}}
        z : int
            Other.
        """

    assert inspect.getdoc(f) == (
        "Do.\n\nParameters\n----------\nx : float\n    The abscissa.\ny : float\n    The ordinate.\nz : int\n    Other."
    )


def test_fill_refuses_a_placeholder_without_entry_and_an_unused_entry():
    with pytest.raises(KeyError):

        @fill()
        def f():
            """{{missing}}"""

    with pytest.raises(ValueError, match="not used"):

        @fill(X, Y)
        def g():
            """{{x}}"""


def test_parameters_appends_the_section_and_refuses_a_second_one():
    @parameters("a : int\n    One.", "b : int\n    Two.")
    def g(a, b):
        """Sum."""

    assert inspect.getdoc(g) == "Sum.\n\nParameters\n----------\na : int\n    One.\nb : int\n    Two."
    with pytest.raises(ValueError):
        parameters("a : int")(g)


def test_parameters_goes_before_the_first_section():
    @parameters("a : int\n    One.")
    def h(a):
        """Twice.

        Returns
        -------
        int
        """

    assert inspect.getdoc(h) == "Twice.\n\nParameters\n----------\na : int\n    One.\n\nReturns\n-------\nint"


def test_attributes_documents_the_fields_from_their_comments():
    from dataclasses import dataclass

    from geardyn._docfill import attributes

    @dataclass(frozen=True)
    @attributes
    class C:
        """A point.

        Notes
        -----
        None.
        """

        #: The name.
        name: str
        #: The coordinates (m),
        #: east then north.
        x: float
        y: float

        z: int = 0  # not documented

        def f(self) -> int:
            w: int = 1  # a local, not a field
            return w

    assert inspect.getdoc(C) == (
        "A point.\n\nAttributes\n----------\nname : str\n    The name.\n"
        "x, y : float\n    The coordinates (m),\n    east then north.\n\n"
        "Notes\n-----\nNone."
    )
