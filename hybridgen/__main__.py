"""``python -m hybridgen`` is the ``hybridgen`` command."""
import sys

from .cli import main

sys.exit(main())
