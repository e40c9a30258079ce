#!/usr/bin/env python3
"""Sets one value inside a JSON section of an ICEF checkpoint and reseals the container.

Usage: edit_checkpoint.py CHECKPOINT SECTION KEY VALUE
  e.g. edit_checkpoint.py model/checkpoint.icef trainer step -1
       edit_checkpoint.py model/checkpoint.icef config train.lambda_id 0.5
KEY is a dotted path inside the section's JSON object; VALUE is JSON text. The file is rewritten
with a correct checksum (io/checkpoint.h: FNV-1a over four interleaved lanes), so the container
check passes and only the reader's checks of the section's content remain. Standard library only.
"""
import json
import struct
import sys

MAGIC = b"ICEFCKPT"
PRIME = 0x100000001B3
MASK = (1 << 64) - 1


def fnv1a64(data, h=0xCBF29CE484222325):
    lanes = [h, h ^ 0x9E3779B97F4A7C15, h ^ 0xBF58476D1CE4E5B9, h ^ 0x94D049BB133111EB]
    n4 = len(data) - len(data) % 4
    for k in range(4):
        lane = lanes[k]
        for byte in data[k:n4:4]:
            lane = ((lane ^ byte) * PRIME) & MASK
        lanes[k] = lane
    for byte in data[n4:]:
        lanes[0] = ((lanes[0] ^ byte) * PRIME) & MASK
    out = h
    for lane in lanes:
        for shift in range(0, 64, 8):
            out = ((out ^ ((lane >> shift) & 0xFF)) * PRIME) & MASK
    return out


def read_sections(data):
    if data[:8] != MAGIC:
        sys.exit("not an ICEF checkpoint")
    version, count = struct.unpack_from("<II", data, 8)
    pos, sections = 16, []
    for _ in range(count):
        (name_len,) = struct.unpack_from("<I", data, pos)
        name = data[pos + 4:pos + 4 + name_len].decode()
        pos += 4 + name_len
        (size,) = struct.unpack_from("<Q", data, pos)
        sections.append([name, data[pos + 8:pos + 8 + size]])
        pos += 8 + size
    return version, sections


def main():
    path, section, key, value = sys.argv[1:5]
    with open(path, "rb") as f:
        version, sections = read_sections(f.read())
    for entry in sections:
        if entry[0] == section:
            obj = json.loads(entry[1])
            parts = key.split(".")
            target = obj
            for part in parts[:-1]:
                target = target[part]
            target[parts[-1]] = json.loads(value)
            entry[1] = json.dumps(obj, separators=(",", ":")).encode()
            break
    else:
        sys.exit(f"no section {section}")
    body = MAGIC + struct.pack("<II", version, len(sections))
    for name, payload in sections:
        body += struct.pack("<I", len(name)) + name.encode() + struct.pack("<Q", len(payload)) + payload
    with open(path, "wb") as f:
        f.write(body + struct.pack("<Q", fnv1a64(body)))


if __name__ == "__main__":
    main()
