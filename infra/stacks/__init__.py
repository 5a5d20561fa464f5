"""Stacks compose constructs, add outputs and tags; they hold no resource logic of their own."""
