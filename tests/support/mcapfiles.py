"""Reading an exported MCAP back with libraries other than the one that wrote it."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from mcap.records import Chunk, DataEnd, Schema
from mcap.stream_reader import StreamReader, breakup_chunk
from mcap_ros2.decoder import DecoderFactory
from rosbags.rosbag2 import Reader

__all__ = ["container", "read_back"]


def read_back(path: Path) -> tuple[dict[str, tuple[str, str, int]], dict[str, list[Any]]]:
    """Schemas (name, encoding), counts and decoded messages (log time, message) per topic:
    the container read by rosbags (which checks every chunk's CRC), each message decoded
    by mcap_ros2 from the schema text in the file."""
    factory, table, messages = DecoderFactory(), {}, {}
    with Reader(path) as reader:
        decoders = {c.id: factory.decoder_for("cdr", Schema(
            id=c.id, name=c.msgtype, encoding="ros2msg", data=c.msgdef.data.encode()))
            for c in reader.connections}
        for c in reader.connections:
            table[c.topic] = (c.msgtype, "ros2msg" if c.msgdef.format.name == "MSG" else "?",
                              c.msgcount)
        last = -1
        for connection, stamp, raw in reader.messages():
            assert stamp >= last  # the whole file in log-time order
            last = stamp
            decoder = decoders[connection.id]
            assert decoder is not None
            messages.setdefault(connection.topic, []).append((stamp, decoder(raw)))
    return table, messages


def container(path: Path) -> tuple[set[str], bool, int]:
    """Chunk compressions, whether every chunk carries a CRC, and the data-section CRC; the
    mcap stream reader checks every one of them as it goes."""
    with path.open("rb") as fh:
        records = list(StreamReader(fh, emit_chunks=True, validate_crcs=True).records)
    chunks = [r for r in records if isinstance(r, Chunk)]
    for chunk in chunks:
        breakup_chunk(chunk, validate_crc=True)
    data_end = next(r for r in records if isinstance(r, DataEnd))
    return ({c.compression for c in chunks}, all(c.uncompressed_crc for c in chunks),
            data_end.data_section_crc)
