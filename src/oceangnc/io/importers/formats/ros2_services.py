"""ROS 2 bags that record service and action events (rosbag2 Iron and later: ``ros2 bag record
--all-services``), read topic by topic without them.

rosbags' ``AnyReader`` parses the message definition of every connection when it opens a bag, and a
service event's definition (``test_msgs/srv/BasicTypes_Event``: request and response separated by
``---``) is no message definition it can parse, so the whole bag is refused (rosbags 0.11; rosbag2's own
test bag ``rosbag2_tests/resources/mcap/bag_with_topics_and_service_events``). :class:`TopicsOnlyReader`
opens the bag with rosbags' storage ``Reader``, leaves out the service-event and action channels, builds a
typestore from the remaining connections' own definitions and offers the part of ``AnyReader``'s interface
that :func:`oceangnc.io.importers.formats.ros2.read_rosbag2` uses (``connections``, ``typestore``,
``messages``, ``deserialize``, ``close``). Only public rosbags API is used.
"""

from __future__ import annotations

from pathlib import Path


def is_service_channel(topic: str, msgtype: str) -> bool:
    """A service or action event channel: ``<service>/_service_event`` topics of ``*/srv/*_Event`` types,
    and action topics (``<action>/_action/...``)."""
    return "/srv/" in msgtype or topic.endswith("/_service_event") or "/_action/" in topic


def service_channels(bag: Path) -> list[str]:
    """The bag's service-event and action topics (empty when it has none or is not a rosbag2 bag)."""
    from rosbags.rosbag2 import Reader

    try:
        with Reader(bag) as r:
            return sorted({c.topic for c in r.connections if is_service_channel(c.topic, c.msgtype)})
    except Exception:  # noqa: BLE001 - not readable as rosbag2 here: AnyReader reports it itself
        return []


class TopicsOnlyReader:
    """A rosbag2 bag with its service and action channels left out (see the module docstring)."""

    def __init__(self, bag: Path):
        from rosbags.interfaces import MessageDefinitionFormat
        from rosbags.rosbag2 import Reader
        from rosbags.typesys import Stores, get_types_from_idl, get_types_from_msg, get_typestore

        self._reader = Reader(bag)
        self._reader.open()
        try:
            self.connections = [c for c in self._reader.connections if not is_service_channel(c.topic, c.msgtype)]
            self.skipped = sorted({c.topic for c in self._reader.connections} - {c.topic for c in self.connections})
            types: dict = {}
            for c in self.connections:
                fmt = c.msgdef.format
                if fmt == MessageDefinitionFormat.MSG:
                    types.update(get_types_from_msg(c.msgdef.data, c.msgtype))
                elif fmt == MessageDefinitionFormat.IDL:
                    types.update(get_types_from_idl(c.msgdef.data))
            if not types:
                raise ValueError("no type definitions for its topics")
            self.typestore = get_typestore(Stores.EMPTY)
            self.typestore.register(types)
        except BaseException:
            self._reader.close()
            raise

    def messages(self, connections=None):
        """(connection, time in ns, raw CDR bytes) of the chosen topics, in time order."""
        return self._reader.messages(connections=connections or self.connections)

    def deserialize(self, raw: bytes, msgtype: str):
        """One message from its CDR bytes, with the bag's own definition of its type."""
        return self.typestore.deserialize_cdr(raw, msgtype)

    def close(self) -> None:
        self._reader.close()
