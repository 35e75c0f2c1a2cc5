"""``python -m shakermill.cli``: the ``shakermill`` command without its console script."""

from shakermill.cli import main

main()
