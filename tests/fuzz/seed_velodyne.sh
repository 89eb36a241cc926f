#!/bin/sh
# Makes seed corpora for the Velodyne fuzz targets from the real captures
# (outside the repository: never commit corpora). Usage:
#   tests/fuzz/seed_velodyne.sh ../shared/data/lidar OUTDIR
set -eu
data=$1
out=$2
mkdir -p "$out/decoder" "$out/calibration" "$out/pcap"
for yaml in "$data"/velodyne-*/*.yaml; do
  cp "$yaml" "$out/calibration/$(basename "$(dirname "$yaml")")-$(basename "$yaml")"
done
for capture in "$data"/velodyne-*/capture.pcap; do
  name=$(basename "$(dirname "$capture")")
  head -c 8192 "$capture" > "$out/pcap/$name.pcap"
  # Payloads of the first records (Ethernet+IPv4+UDP = 42 bytes before the payload),
  # each prefixed by a model byte 0..3 for the decoder target.
  python3 - "$capture" "$out/decoder/$name" <<'PY'
import struct, sys
data = open(sys.argv[1], 'rb').read()
at, n = 24, 0
while at + 16 <= len(data) and n < 16:
    _, _, caplen, _ = struct.unpack('<IIII', data[at:at + 16])
    payload = data[at + 16 + 42:at + 16 + caplen]
    for model in range(4):
        open(f"{sys.argv[2]}-{n}-{model}", 'wb').write(bytes([model]) + payload)
    at += 16 + caplen
    n += 1
PY
done
