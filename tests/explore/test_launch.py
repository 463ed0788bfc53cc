"""What the served explorer lets in (spinectl.explore.hosts): the names of the address bound, the own pages' loads.

No server here: the guard's decisions as a pure function of the ``Host`` and ``Origin``
headers (RFC 9110, 7.2: ``Host`` is ``host[:port]``, 80 when omitted for http; RFC 6454:
``Origin`` is ``scheme://host[:port]``). The served guard: tests/explore/test_served.py.
"""

from __future__ import annotations

import pytest

from spinectl.errors import ParameterError
from spinectl.explore.hosts import allowed_hosts, fetch_allowed, refusal, request_allowed, url_host

P = 5006


def test_a_loopback_address_allows_itself_and_localhost():
    """127.0.0.1 and ::1 (written with or without brackets) allow their own name and localhost, at their port."""
    assert allowed_hosts("127.0.0.1", P) == {("127.0.0.1", P), ("localhost", P)}
    assert allowed_hosts("::1", P) == allowed_hosts("[::1]", P) == {("::1", P), ("localhost", P)}
    assert allowed_hosts("192.0.2.7", P) == {("192.0.2.7", P)}  # another interface: itself only
    assert ("localhost", P) in allowed_hosts("localhost", P) and ("127.0.0.1", P) in allowed_hosts("localhost", P)


@pytest.mark.parametrize(
    ("address", "message"),
    [
        ("", "--address: must name the interface to listen on, e.g. 127.0.0.1 or ::1 (got '')"),
        ("  ", "--address: must name the interface to listen on, e.g. 127.0.0.1 or ::1 (got '  ')"),
        ("0.0.0.0", "--address: must name one interface: every request's Host is checked against it"),
        ("::", "--address: must name one interface"),
        ("no-such-host.invalid", "--address: must be an IP address or a name of this machine; it does not resolve"),
    ],
)
def test_an_address_of_no_one_interface_is_one_line(address, message):
    """Empty, every interface (no one name to check a Host against), a name that does not resolve (RFC 6761:
    .invalid never does)."""
    with pytest.raises(ParameterError) as raised:
        allowed_hosts(address, P)
    assert str(raised.value).startswith(message) and "\n" not in str(raised.value)


ALLOWED = allowed_hosts("127.0.0.1", P)


@pytest.mark.parametrize(
    ("host", "origin", "allowed"),
    [
        (f"127.0.0.1:{P}", None, True),
        (f"localhost:{P}", f"http://localhost:{P}", True),
        (f"LOCALHOST:{P}", f"http://127.0.0.1:{P}/", True),  # host names are case-insensitive
        (f"evil.example:{P}", f"http://evil.example:{P}", False),  # the rebinding page
        (f"evil.example:{P}", None, False),
        (f"127.0.0.1:{P}", f"http://evil.example:{P}", False),  # a foreign page calling the explorer
        (f"127.0.0.1:{P}", "null", False),  # a sandboxed or file:// page
        (f"127.0.0.1:{P}", f"https://127.0.0.1:{P}", False),  # not the scheme served
        (f"127.0.0.1:{P + 1}", None, False),
        ("127.0.0.1", None, False),  # port 80
        (f"evil.example@127.0.0.1:{P}", None, False),  # user info is no Host
        (f"127.0.0.1:{P}/x", None, False),
        (f"127.0.0.1:{P}x", None, False),
        (None, None, False),  # every browser sends Host
    ],
)
def test_only_the_bound_names_get_in(host, origin, allowed):
    assert request_allowed(host, origin, ALLOWED) is allowed


def test_ipv6_hosts_are_matched_in_brackets():
    """A browser at http://[::1]:P/ sends Host [::1]:P; a bare ::1:P is no valid Host."""
    six = allowed_hosts("::1", P)
    assert request_allowed(f"[::1]:{P}", f"http://[::1]:{P}", six)
    assert not request_allowed(f"::1:{P}", None, six) and not request_allowed(f"127.0.0.1:{P}", None, six)
    assert (url_host("::1"), url_host("[::1]"), url_host("127.0.0.1")) == ("[::1]", "[::1]", "127.0.0.1")


@pytest.mark.parametrize(
    ("site", "allowed"),
    [
        ("same-origin", True),  # the explorer's own page: its scripts, its websocket
        ("none", True),  # the address typed, a bookmark
        (None, True),  # an older browser, a non-browser client: Host and Origin alone decide
        ("cross-site", False),  # <img src=...> on any page, a link, an <iframe>, window.open
        ("same-site", False),  # a page of another port of this machine
        ("Cross-Site", False),
        ("anything", False),  # no browser sends it: a forgery
    ],
)
def test_only_the_explorers_own_pages_and_the_user_load_it(site, allowed):
    """W3C Fetch Metadata: the values a browser sends in Sec-Fetch-Site."""
    assert fetch_allowed(site) is allowed


def test_a_refusal_says_why_in_one_line():
    """Host first (DNS rebinding), then Sec-Fetch-Site with the destination the browser gave."""
    own = {"Host": f"127.0.0.1:{P}"}
    assert refusal(own, ALLOWED) is None and refusal({**own, "Sec-Fetch-Site": "none"}, ALLOWED) is None
    image = {**own, "Sec-Fetch-Site": "cross-site", "Sec-Fetch-Mode": "no-cors", "Sec-Fetch-Dest": "image"}
    assert refusal(image, ALLOWED) == (
        "Sec-Fetch-Site 'cross-site' (Sec-Fetch-Dest 'image'): a page of another site made this request; "
        "open the explorer's address in the browser yourself"
    )
    rebinding = {"Host": f"evil.example:{P}", "Sec-Fetch-Site": "same-origin"}  # same origin: the rebound name's
    assert (
        refusal(rebinding, ALLOWED)
        == f"Host 'evil.example:{P}', Origin None is not the address the explorer is bound to"
    )
    long = refusal({**own, "Sec-Fetch-Site": "x" * 1000 + "\n"}, ALLOWED)
    assert "\n" not in long and len(long) < 250  # a forged header is quoted shortened, on one line


@pytest.mark.parametrize("bound", [0, 65, 2.0, True])
def test_a_bound_of_sessions_out_of_range_is_one_line(bound):
    """serve_explorer() as a library call: refused before Panel is imported or a port bound."""
    from spinectl.explore.launch import serve_explorer
    from spinectl.model.config import load_preset

    with pytest.raises(ParameterError, match=r"^--max-sessions: must be an integer"):
        serve_explorer(load_preset(), "default", P, max_sessions=bound)
