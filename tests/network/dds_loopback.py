"""DDS confined to loopback for the ROS 2 network tests: unicast discovery to 127.0.0.1, no multicast, a domain of its own."""

from __future__ import annotations

import os
import random
from pathlib import Path

LOOPBACK_DDS = """<CycloneDDS><Domain id="any"><General><Interfaces><NetworkInterface address="127.0.0.1"/></Interfaces>
<AllowMulticast>false</AllowMulticast></General><Discovery><ParticipantIndex>auto</ParticipantIndex>
<MaxAutoParticipantIndex>40</MaxAutoParticipantIndex><Peers><Peer address="127.0.0.1"/></Peers></Discovery></Domain></CycloneDDS>
"""
"""A cyclonedds configuration (``CYCLONEDDS_URI``) that uses nothing but loopback."""


def loopback_environment(folder: Path, salt: int) -> dict[str, str]:
    """This process's environment with DDS on loopback (its configuration written in ``folder``) and a ROS 2 domain.

    The domain is drawn from the process id and ``salt``, so that test runs side
    by side on one machine, and the tests of one run, keep apart.
    """
    config = folder / "cyclonedds.xml"
    config.write_text(LOOPBACK_DDS, encoding="utf-8")
    domain = random.Random(os.getpid() * 7 + salt).randrange(1, 200)
    return dict(os.environ, CYCLONEDDS_URI=config.as_uri(), ROS_DOMAIN_ID=str(domain))
