"""``python -m hybridgen`` is the ``hybridgen`` command."""
from .cli import console_main

console_main()
