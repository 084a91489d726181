"""The one exception a user can cause: bad input, reported in one line."""


class InputError(Exception):
    """Bad user input; the message names the file, row, column or parameter.

    The CLI prints ``fvd-bridge: <message>`` and exits with code 2.
    """
