"""``python -m sphgen ...``: the same command line as ``sphgen ...``."""
from sphgen.app import main

if __name__ == "__main__":
    main()
