"""What robots say to each other: messages and their binary codec."""

from mrmp.protocol.codec import MAX_MESSAGE_BYTES, PROTOCOL_VERSION, DecodeError, decode, encode
from mrmp.protocol.messages import Message, StateMessage

__all__ = [
    "MAX_MESSAGE_BYTES",
    "PROTOCOL_VERSION",
    "DecodeError",
    "Message",
    "StateMessage",
    "decode",
    "encode",
]
