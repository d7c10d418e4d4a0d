#!/usr/bin/env python3
"""Rewrites top-level elements of a DICOM file as a careless scanner or a
hostile file would have them (the tests' probes; pydicom is not a dependency).

    dicom_edit.py IN OUT TAG=VALUE ...
    dicom_edit.py IN OUT [IN OUT ...] -- TAG=VALUE ...   (the same edits on many files)

TAG is "gggg,eeee". VALUE is text for string elements (DS, IS, ...), "us:N"
for a 16-bit number (Rows, Columns, ...), "shift:D1,D2,..." to add D1, D2, ...
to a multi-valued decimal string's values (0 leaves one as it is),
"cut:N" to keep only the first N
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


def main():
    # One process for many files: a test's loop over slices otherwise
    # spends most of its time starting Python.
    args = sys.argv[1:]
    files, edits = (args[:args.index("--")], args[args.index("--") + 1:]) if "--" in args else (args[:2], args[2:])
    if len(files) < 2 or len(files) % 2:
        raise SystemExit("dicom_edit.py: expected IN OUT pairs, found " + " ".join(files))
    for source, target in zip(files[::2], files[1::2]):
        edit_file(source, target, edits)


def edit_file(source, target, edits):
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
        if edit.startswith("shift:"):
            parts = value.decode().rstrip(" \0").split("\\")
            shifts = [float(d) for d in edit[6:].split(",")]
            if len(shifts) != len(parts):
                raise SystemExit(f"dicom_edit.py: {edit} for {len(parts)} values")
            edit = "\\".join(f"{float(p) + d:.7g}" if d else p for p, d in zip(parts, shifts))
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
