"""``python -m geardyn.cli``: the same as the ``geardyn`` command."""

from . import main

main()
