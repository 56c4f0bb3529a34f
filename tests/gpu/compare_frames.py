"""Compares two folders of PNG frames of the same names within a tolerance:
every channel of every pixel, colour taken premultiplied by its alpha,
within MAX_DIFF (out of 255), and at most MAX_FRACTION of all channel
values different at all.

usage: compare_frames.py BASE_DIR OTHER_DIR MAX_DIFF MAX_FRACTION
Prints one line per frame and a summary; exits 0 within the tolerance, 1
outside it, 2 when a frame is missing or unreadable."""
import os
import sys
import zlib

from png_rgba import decode


def premultiplied_difference(a, b, i):
    """The difference at channel value i as a viewer sees it: colour
    channels times their pixel's alpha (what the pixel adds over any
    background), rounded to bytes, and alpha as it is. In straight alpha a
    faint pixel's colour is its light divided by a tiny alpha, so two
    rasterisers that differ by 1e-6 in that light can differ by 255 in the
    colour byte of a pixel that is, in both, fully transparent."""
    if i % 4 == 3:
        return abs(a[i] - b[i])
    alpha = i - i % 4 + 3
    return abs(round(a[i] * a[alpha] / 255) - round(b[i] * b[alpha] / 255))


def main():
    ref_dir, other_dir = sys.argv[1], sys.argv[2]
    max_diff, max_fraction = int(sys.argv[3]), float(sys.argv[4])
    names = sorted(n for n in os.listdir(ref_dir) if n.endswith(".png"))
    if not names:
        print(f"no PNG frames in {ref_dir}")
        return 2
    worst, differing, total = 0, 0, 0
    for name in names:
        try:
            w, h, a = decode(os.path.join(ref_dir, name))
            w2, h2, b = decode(os.path.join(other_dir, name))
        except (OSError, ValueError, zlib.error) as e:
            print(f"cannot read {name}: {e}")
            return 2
        if (w, h) != (w2, h2):
            print(f"{name}: {w}x{h} against {w2}x{h2}")
            return 1
        diffs = [premultiplied_difference(a, b, i) for i in range(len(a))]
        frame_worst, frame_differing = max(diffs), sum(d > 0 for d in diffs)
        at = diffs.index(frame_worst)
        px = at // 4
        print(f"{name}: largest difference {frame_worst}/255 at ({px % w}, {px // w}) "
              f"{tuple(a[4 * px:4 * px + 4])} against {tuple(b[4 * px:4 * px + 4])}, "
              f"{frame_differing} of {len(a)} values differ")
        worst = max(worst, frame_worst)
        differing += frame_differing
        total += len(a)
    fraction = differing / total
    print(f"all: largest difference {worst}/255 (at most {max_diff}), "
          f"{fraction:.4%} of values differ (at most {max_fraction:.4%})")
    return 0 if worst <= max_diff and fraction <= max_fraction else 1


sys.exit(main())
