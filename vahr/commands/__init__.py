"""Thin command-line front ends of `vahr`, one module per subcommand."""
