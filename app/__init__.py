"""Lagrange Lab's web layer: the JSON API over the engine in ``mechanics`` (and, later, its pages).

Data flows one way, spec -> engine -> API; nothing in ``mechanics`` imports this package.
"""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("lagrange-lab")
except PackageNotFoundError:  # running from a checkout that was never pip-installed
    __version__ = "0+unknown"
