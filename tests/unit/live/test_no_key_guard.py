"""The no-key guard's reading of hosts and endpoints: only what is provably loopback may go without a fleet key."""

import json

import pytest

from mrmp.core.errors import InputError
from mrmp.live.process import check_key_policy
from mrmp.live.transport import is_loopback
from mrmp.live.transport_table import TRANSPORTS, MulticastOptions, TransportSpec, UdpOptions
from mrmp.live.zenoh_transport import ZenohEndpoint

IDS = ["A", "B"]


def refused(spec):
    with pytest.raises(InputError) as error:
        check_key_policy(b"", spec, pytest.fail)
    (problem,) = error.value.problems
    assert problem.where == "--key-file" and "no fleet key: refusing to talk to" in problem.reason
    return problem.reason


@pytest.mark.parametrize("host", ["127.0.0.1", "127.3.4.5", "localhost", "::1", "[::1]"])
def test_loopback_hosts(host):
    assert is_loopback(host)


@pytest.mark.parametrize("host", ["", "0.0.0.0", "::", "10.0.0.1", "127.1", "0x7f.1", "2130706433", "127.0.0.1 x",
                                  "127.0.0.1\n10.0.0.1", "::ffff:127.0.0.1", "localhost.example.org"])  # fmt: skip
def test_not_provably_loopback_hosts(host):
    assert not is_loopback(host)


@pytest.mark.parametrize(
    ("listen", "named"),
    [("tcp/0.0.0.0:17450?x=/", "tcp/0.0.0.0:17450?x=/"), ("tcp/0.0.0.0:17450#a/b", "tcp/0.0.0.0:17450#a/b"),
     ("tcp/:17450", "''"), ("tcp/[::]:17450", "::"), ("tcp/127.0.0.1:17450#iface=eth0", "#iface=eth0"),
     ("tcp/127.0.0.1:17450?prio=1", "?prio=1"), ("unixsock-stream//tmp/robot", "unixsock-stream//tmp/robot"),
     ("quic/127.0.0.1:17450", "quic/127.0.0.1:17450")],
)  # fmt: skip
def test_a_keyless_zenoh_endpoint_that_is_not_provably_loopback_is_refused(listen, named):
    spec = TRANSPORTS.parse("zenoh", {"listen": listen, "connect": ["tcp/127.0.0.1:17451"], "fleet": "mrmp"}, IDS, 0)
    assert named in refused(spec)


@pytest.mark.parametrize("listen", ["tcp/127.0.0.1:17450", "udp/127.0.0.1:17450", "tcp/localhost:17450", "tcp/[::1]:17450"])
def test_a_keyless_zenoh_endpoint_on_loopback_is_allowed_with_a_warning(listen):
    spec = TRANSPORTS.parse("zenoh", {"listen": listen, "connect": ["tcp/127.0.0.1:17451"], "fleet": "mrmp"}, IDS, 0)
    warnings = []
    assert check_key_policy(b"", spec, warnings.append) == b""
    assert "NOT authenticated" in warnings[0]


def test_a_keyless_zenoh_peer_beyond_loopback_is_refused_and_a_key_allows_everything():
    spec = TRANSPORTS.parse("zenoh", {"listen": "tcp/127.0.0.1:1", "connect": ["tcp/10.0.0.2:1?x=/"], "fleet": "m"}, IDS, 0)
    assert "tcp/10.0.0.2:1?x=/" in refused(spec)
    assert check_key_policy(b"k" * 16, spec, pytest.fail) == b"k" * 16


def test_keyless_udp_and_multicast_beyond_loopback_are_refused():
    assert "0.0.0.0" in refused(TransportSpec("udp", UdpOptions(("0.0.0.0", 9001), {1: ("127.0.0.1", 9002)})))
    assert "10.0.0.2" in refused(TransportSpec("udp", UdpOptions(("127.0.0.1", 9001), {1: ("10.0.0.2", 9002)})))
    assert "''" in refused(TransportSpec("multicast", MulticastOptions(("239.255.77.1", 47000), "")))
    assert "10.0.0.1" in refused(TransportSpec("multicast", MulticastOptions(("239.255.77.1", 47000), "10.0.0.1")))


@pytest.mark.parametrize(
    ("text", "parts"),
    [
        ("tcp/0.0.0.0:17450?x=/", ("tcp", "0.0.0.0:17450", "x=/", "")),
        ("tcp/0.0.0.0:17450#a/b", ("tcp", "0.0.0.0:17450", "", "a/b")),
        ("tcp/1.2.3.4:5?a=1#b=2", ("tcp", "1.2.3.4:5", "a=1", "b=2")),
        ("tcp/a?b?c", ("tcp", "a", "b?c", "")),
        ("tcp/a#b#c", ("tcp", "a", "", "b#c")),
        ("unixsock-stream//tmp/x", ("unixsock-stream", "/tmp/x", "", "")),
    ],
)
def test_endpoints_split_as_zenoh_splits_them(text, parts):
    endpoint = ZenohEndpoint.parse(text)
    assert (endpoint.protocol, endpoint.address, endpoint.metadata, endpoint.config) == parts


BAD_ENDPOINTS = ["tcp127.0.0.1:7447", "tcp/", "/127.0.0.1:7447", "tcp/127.0.0.1:7447?", "tcp/127.0.0.1:7447#",
                 "tcp/1.2.3.4:5#b=2?a=1", "t?cp/1:2", "t#cp/1:2", ""]  # fmt: skip


@pytest.mark.parametrize("text", BAD_ENDPOINTS)
def test_an_endpoint_refused_here_is_one_zenoh_refuses(text):
    with pytest.raises(ValueError, match="expected a Zenoh endpoint"):
        ZenohEndpoint.parse(text)
    zenoh = pytest.importorskip("zenoh")
    with pytest.raises(zenoh.ZError):
        zenoh.Config().insert_json5("listen/endpoints", json.dumps([text]))
