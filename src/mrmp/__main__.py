"""``python -m mrmp`` runs the ``mrmp`` command."""

from mrmp.cli import main

main()
