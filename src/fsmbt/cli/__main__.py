import sys

from fsmbt.cli import main

sys.exit(main())
