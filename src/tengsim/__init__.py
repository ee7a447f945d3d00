"""tengsim: adhesive contact of micro-structured TENG interfaces and the device output."""
__version__ = "0.1.0"
