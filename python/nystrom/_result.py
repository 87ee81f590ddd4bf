"""The base of the module's result objects: a dict whose keys are also attributes (as scipy's OptimizeResult)."""


class AttrDict(dict):
    """A dict whose keys read and write as attributes; pickles as a plain dict of its items."""

    def __getattr__(self, name):
        try:
            return self[name]
        except KeyError:
            raise AttributeError(name) from None

    __setattr__ = dict.__setitem__

    def __reduce__(self):
        return (type(self), (dict(self),))
