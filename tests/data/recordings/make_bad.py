#!/usr/bin/env python3
"""Makes the damaged recordings of tests/data/recordings/ from diffusion/recording.swrec
(FORMAT.md): truncated/ (cut inside its last step record, no end chunk), corrupt/ (one
payload byte of chunk 10 flipped: a checksum mismatch) and newer_version/ (its header
says version [2, 0]). Needs the zstd program. Run from this folder."""
import json, os, struct, subprocess

def xxh32(b):
    P1, P2, P3, P4, P5 = 2654435761, 2246822519, 3266489917, 668265263, 374761393
    M = 0xFFFFFFFF
    rotl = lambda x, r: ((x << r) | (x >> (32 - r))) & M
    rd = lambda i: struct.unpack_from('<I', b, i)[0]
    rnd = lambda acc, lane: (rotl((acc + lane * P2) & M, 13) * P1) & M
    n, i = len(b), 0
    if n >= 16:
        v = [(P1 + P2) & M, P2, 0, (-P1) & M]
        while i + 16 <= n:
            v = [rnd(v[k], rd(i + 4 * k)) for k in range(4)]
            i += 16
        h = (rotl(v[0], 1) + rotl(v[1], 7) + rotl(v[2], 12) + rotl(v[3], 18)) & M
    else:
        h = P5
    h = (h + n) & M
    while i + 4 <= n:
        h = (rotl((h + rd(i) * P3) & M, 17) * P4) & M
        i += 4
    while i < n:
        h = (rotl((h + b[i] * P5) & M, 11) * P1) & M
        i += 1
    h = ((h ^ (h >> 15)) * P2) & M
    h = ((h ^ (h >> 13)) * P3) & M
    return h ^ (h >> 16)

def chunks(data):
    at = 0
    while at < len(data):
        kind, step, stored, raw, check = struct.unpack_from('<BxxxIIII', data, at + 4)
        assert xxh32(data[at + 24:at + 24 + stored]) == check
        yield at, kind, step, stored, raw
        at += 24 + stored

def write(folder, data):
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, 'recording.swrec'), 'wb') as f:
        f.write(data)

data = open('diffusion/recording.swrec', 'rb').read()
table = list(chunks(data))
# Cut inside the last step record (the chunk before the end chunk).
at, kind, step, stored, raw = table[-2]
write('truncated', data[:at + 24 + stored // 2])
at, kind, step, stored, raw = table[10]
corrupt = bytearray(data)
corrupt[at + 24 + stored // 2] ^= 0x40
write('corrupt', bytes(corrupt))
at, kind, step, stored, raw = table[0]
header = json.loads(subprocess.run(['zstd', '-dc'], input=data[24:24 + stored],
                                   capture_output=True, check=True).stdout)
header['version'] = [2, 0]
payload = json.dumps(header).encode()
packed = subprocess.run(['zstd', '-c', '-q'], input=payload, capture_output=True, check=True).stdout
chunk = b'SWRC' + struct.pack('<BxxxIIII', 1, 0, len(packed), len(payload), xxh32(packed)) + packed
write('newer_version', chunk + data[24 + stored:])
