"""SwiftFin: parametric CAD and mechanism-design generator for a capstan-driven robotic tuna."""
from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("swiftfin")
except PackageNotFoundError:  # running from a source tree without installation
    __version__ = "0.0.0+src"
