"""Placeholder package: its code lands with its own issue."""
