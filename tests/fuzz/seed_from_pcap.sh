#!/bin/sh
# Writes each UDP payload of a classic pcap (Ethernet/IPv4/UDP) to OUT_DIR as
# one seed file, for libFuzzer corpora: seed_from_pcap.sh CAPTURE.pcap OUT_DIR [MAX]
set -eu
capture=$1 out=$2 max=${3:-200}
mkdir -p "$out"
python3 - "$capture" "$out" "$max" <<'PY'
import struct, sys, os
capture, out, limit = sys.argv[1], sys.argv[2], int(sys.argv[3])
data = open(capture, 'rb').read()
link = struct.unpack('<I', data[20:24])[0]
off, n = 24, 0
while off + 16 <= len(data) and n < limit:
    _, _, incl, _ = struct.unpack('<IIII', data[off:off + 16])
    frame = data[off + 16:off + 16 + incl]
    off += 16 + incl
    ip = frame[14:] if link == 1 else frame
    if len(ip) < 28 or ip[9] != 17:
        continue
    ihl = (ip[0] & 15) * 4
    open(os.path.join(out, 'seed%05d' % n), 'wb').write(ip[ihl + 8:])
    n += 1
PY
