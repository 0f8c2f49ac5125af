"""``python -m lptv ...`` runs the ``lptv`` command."""
import sys

from lptv.apps.cli import main

sys.exit(main())
