#!/usr/bin/env python3
"""Rewrites top-level elements of a DICOM file as a careless scanner or a
hostile file would have them (the tests' probes; pydicom is not a dependency).

    dicom_edit.py IN OUT TAG=VALUE ...

TAG is "gggg,eeee". VALUE is text for string elements (DS, IS, ...), "us:N"
for a 16-bit number (Rows, Columns, ...), "cut:N" to keep only the first N
bytes of the element's value (its length then says N: a slice whose pixel data
is short of what its Rows x Columns announce), or "drop" to remove it. A text
or number for an element the file lacks inserts it in its place.
Reads and writes the meta header in explicit VR little endian and the data set
in implicit VR little endian, as `articula phantom` writes them.
"""
import struct
import sys


def elements(data, start, explicit):
    pos = start
    while pos < len(data):
        group, element = struct.unpack_from("<HH", data, pos)
        if explicit:
            vr = data[pos + 4:pos + 6]
            if vr in (b"OB", b"OW", b"OF", b"SQ", b"UT", b"UN"):
                length, head = struct.unpack_from("<I", data, pos + 8)[0], 12
            else:
                length, head = struct.unpack_from("<H", data, pos + 6)[0], 8
        else:
            vr, length, head = None, struct.unpack_from("<I", data, pos + 4)[0], 8
        if length == 0xFFFFFFFF:
            raise SystemExit("dicom_edit.py: elements of undefined length are not handled")
        yield (group, element), pos, head, length, vr
        pos += head + length


def meta_end(data):
    end = 132
    for (group, _), pos, head, length, _ in elements(data, 132, True):
        if group != 0x0002:
            break
        end = pos + head + length
    return end


def value(path, tag):
    """The text of a top-level element, e.g. value(f, "0020,0032")."""
    data = open(path, "rb").read()
    want = tuple(int(x, 16) for x in tag.split(","))
    for found, pos, head, length, _ in elements(data, meta_end(data), False):
        if found == want:
            return data[pos + head:pos + head + length].decode().rstrip(" \0")
    raise SystemExit(f"dicom_edit.py: {path} has no element {tag}")


def main():
    source, target, *edits = sys.argv[1:]
    data = bytearray(open(source, "rb").read())
    assert data[128:132] == b"DICM", source
    end = meta_end(data)
    wanted = {}
    for edit in edits:
        tag, value = edit.split("=", 1)
        g, e = (int(x, 16) for x in tag.split(","))
        wanted[(g, e)] = value
    out = bytearray(data[:end])

    def put(tag, value):
        out.extend(struct.pack("<HHI", tag[0], tag[1], len(value)) + value)

    def edited(edit, value):
        if edit.startswith("us:"):
            return struct.pack("<H", int(edit[3:]))
        if edit.startswith("cut:"):
            return value[:int(edit[4:])]
        value = edit.encode()
        return value + b" " if len(value) % 2 else value

    for tag, pos, head, length, _ in elements(data, end, False):
        for missing in sorted(t for t in wanted if t < tag and not wanted[t].startswith(("drop", "cut:"))):
            put(missing, edited(wanted.pop(missing), b""))
        value = bytes(data[pos + head:pos + head + length])
        edit = wanted.pop(tag, None)
        if edit == "drop":
            continue
        put(tag, value if edit is None else edited(edit, value))
    if wanted:
        raise SystemExit(f"dicom_edit.py: {source} has no element {sorted(wanted)}")
    open(target, "wb").write(out)


if __name__ == "__main__":
    main()
