"""``python -m fepost``: the same as the ``fepost`` command."""

from .cli import console_main

if __name__ == "__main__":
    console_main()
