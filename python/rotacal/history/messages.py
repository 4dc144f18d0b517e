# SPDX-License-Identifier: BSD-3-Clause
"""How the history names a store and an error in its messages: a location with its password
hidden, an exception on one line."""

from __future__ import annotations

from urllib.parse import urlsplit


def redact(location: str) -> str:
    """A store location fit to print: the password of a URL replaced by ***."""
    if "://" not in location:
        return location
    try:
        parts = urlsplit(location)
    except ValueError:
        return location.split("://", 1)[0] + "://..."
    if parts.password is None:
        return location
    netloc = parts.netloc.replace(f":{parts.password}@", ":***@", 1)
    return parts._replace(netloc=netloc).geturl()


def one_line(e: BaseException) -> str:
    return " ".join(str(e).split())
