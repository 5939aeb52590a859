"""``python -m rotomorph``: the command line (:mod:`rotomorph.cli`)."""

from rotomorph.cli import entry_point

if __name__ == "__main__":
    entry_point()
