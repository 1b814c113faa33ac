"""fretsim: fast, verified simulation of fretting wear (after Kong, Bennett & Hyde)."""
__version__ = "0.1.0"
