"""The installed version of tengsim: set from the git tag at build time (setuptools-scm), read here."""
from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("tengsim")
except PackageNotFoundError:  # a source tree that was never installed
    __version__ = "0+unknown"
