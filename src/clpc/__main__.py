"""``python -m clpc``: the same command line as the ``clpc`` console script."""

from clpc.cli import run

if __name__ == "__main__":
    run()
