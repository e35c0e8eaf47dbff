#!/usr/bin/env python3
"""Reads a TensorBoard event file with Python's protobuf, independently of masa's reader: the record
framing and CRC-32C are checked here, and the Event, Summary, Value, SummaryMetadata and TensorProto
messages are declared by their field numbers (TensorFlow's summary.proto, event.proto, tensor.proto).
Prints one line per record: step, then "version V", "scalar TAG VALUE" or "text TAG TEXT".
  python3 tests/tools/read_tfevents.py FILE"""
import struct
import sys

from google.protobuf import descriptor_pb2, descriptor_pool, message_factory


def crc32c(data):
    crc = 0xFFFFFFFF
    for b in data:
        crc ^= b
        for _ in range(8):
            crc = (crc >> 1) ^ 0x82F63B78 if crc & 1 else crc >> 1
    return crc ^ 0xFFFFFFFF


def masked(data):
    c = crc32c(data)
    return (((c >> 15) | (c << 17)) + 0xA282EAD8) & 0xFFFFFFFF


def messages():
    f = descriptor_pb2.FileDescriptorProto(name="tfevents_check.proto", package="check", syntax="proto3")
    T = descriptor_pb2.FieldDescriptorProto

    def msg(name, fields):
        m = f.message_type.add(name=name)
        for fname, number, ftype, label, type_name in fields:
            fd = m.field.add(name=fname, number=number, type=ftype, label=label)
            if type_name:
                fd.type_name = ".check." + type_name
    opt, rep = T.LABEL_OPTIONAL, T.LABEL_REPEATED
    msg("PluginData", [("plugin_name", 1, T.TYPE_STRING, opt, None)])
    msg("SummaryMetadata", [("plugin_data", 1, T.TYPE_MESSAGE, opt, "PluginData")])
    msg("TensorProto", [("dtype", 1, T.TYPE_INT32, opt, None), ("string_val", 8, T.TYPE_BYTES, rep, None)])
    msg("Value", [("tag", 1, T.TYPE_STRING, opt, None), ("simple_value", 2, T.TYPE_FLOAT, opt, None),
                  ("tensor", 8, T.TYPE_MESSAGE, opt, "TensorProto"), ("metadata", 9, T.TYPE_MESSAGE, opt, "SummaryMetadata")])
    msg("Summary", [("value", 1, T.TYPE_MESSAGE, rep, "Value")])
    msg("Event", [("wall_time", 1, T.TYPE_DOUBLE, opt, None), ("step", 2, T.TYPE_INT64, opt, None),
                  ("file_version", 3, T.TYPE_STRING, opt, None), ("summary", 5, T.TYPE_MESSAGE, opt, "Summary")])
    pool = descriptor_pool.DescriptorPool()
    pool.Add(f)
    return message_factory.MessageFactory(pool).GetPrototype(pool.FindMessageTypeByName("check.Event"))


def main(path):
    Event = messages()
    data = open(path, "rb").read()
    at = 0
    while at < len(data):
        (n,) = struct.unpack_from("<Q", data, at)
        (len_crc,) = struct.unpack_from("<I", data, at + 8)
        assert len_crc == masked(data[at:at + 8]), f"length CRC at byte {at}"
        body = data[at + 12:at + 12 + n]
        (body_crc,) = struct.unpack_from("<I", data, at + 12 + n)
        assert body_crc == masked(body), f"data CRC at byte {at}"
        e = Event()
        e.ParseFromString(body)
        if e.file_version:
            print(e.step, "version", e.file_version)
        for v in e.summary.value:
            if v.metadata.plugin_data.plugin_name == "text":
                assert v.tensor.dtype == 7, "a text tensor is DT_STRING"
                print(e.step, "text", v.tag, v.tensor.string_val[0].decode())
            else:
                print(e.step, "scalar", v.tag, repr(v.simple_value))
        at += 12 + n + 4


if __name__ == "__main__":
    main(sys.argv[1])
