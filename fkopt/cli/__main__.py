"""``python -m fkopt.cli``: the ``fkopt`` program (as the Makefile and the tests run it)."""
from fkopt.cli.entry_point import main

if __name__ == "__main__":
    main()
