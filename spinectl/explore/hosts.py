"""Which requests the explorer's server answers: the guard against DNS rebinding and other sites' pages.

:func:`allowed_hosts` gives the names a request may address the server by, and
:func:`request_allowed` checks a request's ``Host`` and ``Origin`` against them
(docs/explore.md, "Who can reach it"): a page of another site whose name is made to
resolve to this machine is served by the browser as that site, so the ``Host`` and
``Origin`` it sends name that site, not the address bound; such requests are refused.
:func:`fetch_allowed` refuses what a page of another site makes the browser load from the
explorer without an ``Origin`` (an ``<img>``, an ``<iframe>``, a link): the browser says so in
``Sec-Fetch-Site``. :func:`refusal` is both, in one line. Pure functions, apart from the
server (:mod:`spinectl.explore.server`) that uses them.
"""

from __future__ import annotations

import ipaddress
import socket
import urllib.parse
from collections.abc import Mapping

from .._validate import show
from ..errors import ParameterError

LOCALHOST = "localhost"
"""The loopback interface's name, which browsers resolve to the loopback addresses themselves."""
HTTP_PORT = 80
"""The port a ``Host`` or ``Origin`` without one means (RFC 9110, section 4.2.1)."""
MAX_SESSIONS = 8
"""Default bound of the sessions alive at once (``spinectl explore --max-sessions``): a few tabs, each a session."""
SESSIONS_RANGE = (1, 64)
"""The bounds a user may choose from: each session holds its own model, views and landscapes."""
UNUSED_SESSION_S = 15.0
"""How long a session outlives its page, or waits for its page to connect [s] (Bokeh's default)."""
FETCH_SITES = frozenset({"same-origin", "none"})
"""The ``Sec-Fetch-Site`` values let in (W3C Fetch Metadata): the explorer's own pages, and a navigation the user
made (the address typed, a bookmark); ``same-site`` and ``cross-site``, loads a page of another site made, are not."""


def _refused(address: str, why: str) -> ParameterError:
    return ParameterError("--address", f"{why} (got {address!r})")


def allowed_hosts(address: str, port: int) -> frozenset[tuple[str, int]]:
    """The (host, port) pairs by which a request may address a server bound to ``address`` and ``port``.

    An IP address allows itself (an IPv6 one written in brackets in a URL), a loopback address
    ``localhost`` too, and a host name itself and the addresses it resolves to. Nothing else: a
    request whose ``Host`` or ``Origin`` names another site is refused (:func:`request_allowed`).

    Parameters
    ----------
    address : str
        The interface to bind, e.g. ``127.0.0.1``, ``::1`` (or ``[::1]``), ``localhost``.
    port : int
        TCP port.

    Returns
    -------
    frozenset of (str, int)
        Host names, lower case, IPv6 addresses without brackets, each with ``port``.

    Raises
    ------
    ParameterError
        An empty address, one of every interface (``0.0.0.0``, ``::``: no one name to check a
        request against), or a name that does not resolve.
    """
    name = address.strip()
    if name.startswith("[") and name.endswith("]"):
        name = name[1:-1]
    if not name:
        raise _refused(address, "must name the interface to listen on, e.g. 127.0.0.1 or ::1")
    try:
        ip = ipaddress.ip_address(name)
    except ValueError:
        ip = None
    if ip is not None:
        if ip.is_unspecified:
            raise _refused(
                address,
                "must name one interface: every request's Host is checked against it, and this one "
                "stands for all of them; give the address of the one to serve on",
            )
        names = {ip.compressed} | ({LOCALHOST} if ip.is_loopback else set())
        return frozenset((n, port) for n in names)
    try:
        resolved = socket.getaddrinfo(name, port, type=socket.SOCK_STREAM)
    except (OSError, UnicodeError) as exc:
        why = f"must be an IP address or a name of this machine; it does not resolve ({exc})"
        raise _refused(address, why) from None
    names = {name.lower()} | {ipaddress.ip_address(info[4][0].split("%")[0]).compressed for info in resolved}
    return frozenset((n, port) for n in names)


def url_host(address: str) -> str:
    """``address`` as written in a URL: an IPv6 address in brackets.

    Parameters
    ----------
    address : str

    Returns
    -------
    str
        E.g. ``127.0.0.1``, ``[::1]``, ``localhost``.
    """
    name = address.strip().strip("[]")
    return f"[{name}]" if ":" in name else name


def _host_port(netloc: str) -> tuple[str, int] | None:
    """``host[:port]`` as (host, port), or None if it is not exactly that (user info, a path, a bad port)."""
    parts = urllib.parse.urlsplit("//" + netloc)
    try:
        port = parts.port
    except ValueError:
        return None
    if parts.netloc != netloc or "@" in netloc or parts.path or parts.query or not parts.hostname:
        return None
    return parts.hostname.lower(), HTTP_PORT if port is None else port


def request_allowed(host: str | None, origin: str | None, allowed: frozenset[tuple[str, int]]) -> bool:
    """Whether a request with these ``Host`` and ``Origin`` headers addresses the server as bound.

    A browser always sends ``Host``, and ``Origin`` with every websocket and cross-site request;
    a DNS-rebinding page sends its own site's name in both.

    Parameters
    ----------
    host : str or None
        The ``Host`` header; missing is refused.
    origin : str or None
        The ``Origin`` header; missing is allowed (a same-origin page load, a non-browser client),
        present it must be ``http://`` and a pair of ``allowed``.
    allowed : frozenset of (str, int)
        :func:`allowed_hosts`.

    Returns
    -------
    bool
    """
    if host is None or _host_port(host) not in allowed:
        return False
    if origin is None:
        return True
    parts = urllib.parse.urlsplit(origin)
    return parts.scheme == "http" and parts.path in ("", "/") and _host_port(parts.netloc) in allowed


def fetch_allowed(site: str | None) -> bool:
    """Whether a request with this ``Sec-Fetch-Site`` header comes from the explorer's pages or from the user.

    A browser sends it with every request (W3C Fetch Metadata): ``same-origin`` from the explorer's
    own page, ``none`` for the address typed or a bookmark, ``same-site`` or ``cross-site`` for what a
    page of another site loads, a navigation included (an ``<img src>``, an ``<iframe>``, a link, a
    redirect). Those two are refused: each page served builds a session, a core busy for seconds.

    Parameters
    ----------
    site : str or None
        The header; missing (an older browser, a non-browser client) is allowed: the ``Host`` and
        ``Origin`` checks still apply (:func:`request_allowed`).

    Returns
    -------
    bool
    """
    return site is None or site.strip().lower() in FETCH_SITES


def refusal(headers: Mapping[str, str], allowed: frozenset[tuple[str, int]]) -> str | None:
    """Why the server refuses a request with these headers, in one line, or None if it serves it.

    Parameters
    ----------
    headers : mapping of str to str
        The request's headers (``Host``, ``Origin``, ``Sec-Fetch-Site``, ``Sec-Fetch-Dest``), as a
        case-insensitive mapping such as Tornado's.
    allowed : frozenset of (str, int)
        :func:`allowed_hosts`.

    Returns
    -------
    str or None
        E.g. ``Sec-Fetch-Site 'cross-site' (Sec-Fetch-Dest 'image'): a page of another site ...``.
    """
    host, origin, site = (headers.get(name) for name in ("Host", "Origin", "Sec-Fetch-Site"))
    if not request_allowed(host, origin, allowed):
        return f"Host {show(host)}, Origin {show(origin)} is not the address the explorer is bound to"
    if not fetch_allowed(site):
        dest = headers.get("Sec-Fetch-Dest")
        return (
            f"Sec-Fetch-Site {show(site)} (Sec-Fetch-Dest {show(dest)}): a page of another site made this "
            "request; open the explorer's address in the browser yourself"
        )
    return None
