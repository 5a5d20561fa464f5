"""Thin command-line front ends of `robot-agent`, one module per subcommand."""
