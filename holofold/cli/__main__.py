import sys

from holofold.cli import main

sys.exit(main())
