"""``python -m swiftfin``: the same as the ``swiftfin`` command."""
import sys

from swiftfin.cli import main

sys.exit(main())
