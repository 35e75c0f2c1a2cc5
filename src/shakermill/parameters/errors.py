"""The error of bad user input, in a module of its own: the command line catches it without loading the parameters."""


class ParameterError(ValueError):
    """Bad user input: one line naming the key and what is allowed."""
