"""`python -m fretsim` is the `fretsim` command."""
from fretsim.cli import main

main(prog_name="fretsim")
