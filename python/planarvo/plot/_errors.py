"""The one error the command line turns into exit status 2: bad input, said in words."""


class InputError(Exception):
    """Bad input (a file that does not parse, times that match no frame...): exit 2."""
