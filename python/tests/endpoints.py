"""Helpers for looking at a served module's endpoints from a test."""

import socket


def port_open(address):
    """True when something accepts TCP connections at ``host:port``."""
    host, port = address.rsplit(":", 1)
    try:
        with socket.create_connection((host, int(port)), timeout=1):
            return True
    except OSError:
        return False
