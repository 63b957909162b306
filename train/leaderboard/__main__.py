import sys

from acld_gym.util.validate import run_main

from .cli import main

sys.exit(run_main(main))
