import sys

from tmfem.cli import main

sys.exit(main())
