"""`python3 -m fretbuzz.studio [INSTRUMENT] [--port N] [--host H]`: the studio without the fretbuzz program."""
import sys

from . import main

sys.exit(main())
