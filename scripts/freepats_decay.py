#!/usr/bin/python3
"""Write the free decay of a plucked string from a GUS patch (.pat) of Debian's `freepats`
package as a WAV file, for `fretbuzz estimate`.

Usage: freepats_decay.py OUT.wav [--patch PATH] [--sample NAME]

The default is the low E (E2, 82.4 Hz) sample of the nylon-string guitar,
/usr/share/midi/freepats/Tone_000/024_Nylon_Guitar.pat. A GF1 patch holds, after a
129-byte file header, a 63-byte instrument header and a 47-byte layer header, one
96-byte header per sample followed by its PCM data; the data is the recorded note from
the pluck on. The loop points (used by a synthesiser to sustain the note) are ignored:
the whole recorded sample is written, and `fretbuzz estimate` starts after the attack
peak. Prints the sample's rate, length and root note.
"""
import argparse
import math
import struct
import sys
import wave

DEFAULT_PATCH = "/usr/share/midi/freepats/Tone_000/024_Nylon_Guitar.pat"
DEFAULT_SAMPLE = "e1"


def read_samples(path):
    data = open(path, "rb").read()
    if data[:8] != b"GF1PATCH":
        raise ValueError(f"{path}: not a GUS patch (no GF1PATCH header)")
    count = data[129 + 63 + 6]  # the layer header's sample count
    pos = 129 + 63 + 47
    samples = []
    for _ in range(count):
        header = data[pos:pos + 96]
        name = header[0:7].split(b"\0")[0].decode("latin1")
        length, loop_start, loop_end = struct.unpack_from("<III", header, 8)
        rate, = struct.unpack_from("<H", header, 20)
        root_mhz, = struct.unpack_from("<I", header, 30)
        modes = header[55]
        pos += 96
        samples.append({"name": name, "rate": rate, "root_hz": root_mhz / 1000.0, "bits": 16 if modes & 1 else 8,
                        "unsigned": bool(modes & 2), "data": data[pos:pos + length]})
        pos += length
    return samples


def to_pcm16(sample):
    """The sample as signed 16-bit little-endian bytes."""
    raw = sample["data"]
    if sample["bits"] == 16:
        values = struct.unpack(f"<{len(raw) // 2}{'H' if sample['unsigned'] else 'h'}", raw[:len(raw) // 2 * 2])
        if sample["unsigned"]:
            values = [v - 32768 for v in values]
    else:
        values = [((b - 128) if sample["unsigned"] else (b - 256 if b > 127 else b)) * 256 for b in raw]
    return struct.pack(f"<{len(values)}h", *values)


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out")
    parser.add_argument("--patch", default=DEFAULT_PATCH)
    parser.add_argument("--sample", default=DEFAULT_SAMPLE)
    args = parser.parse_args(argv)
    samples = read_samples(args.patch)
    chosen = [s for s in samples if s["name"] == args.sample]
    if not chosen:
        print(f"{args.patch}: no sample {args.sample!r}; it has {[s['name'] for s in samples]}", file=sys.stderr)
        return 2
    s = chosen[0]
    pcm = to_pcm16(s)
    with wave.open(args.out, "wb") as w:
        w.setnchannels(1)
        w.setsampwidth(2)
        w.setframerate(s["rate"])
        w.writeframes(pcm)
    note = 69 + 12 * math.log2(s["root_hz"] / 440.0)
    print(f"{args.patch} sample {s['name']}: {s['rate']} Hz, {len(pcm) // 2 / s['rate']:.2f} s, "
          f"root {s['root_hz']:.3f} Hz (MIDI note {note:.2f})")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
