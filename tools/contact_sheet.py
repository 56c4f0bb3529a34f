#!/usr/bin/python3
"""Contact sheet of rendered frames: each PNG composited over a dark grey
checkerboard (so straight alpha shows as it would over a backdrop), scaled
to a cell, labelled, in a grid. Used to look at frames and to make
docs/examples.png (see README). Needs python3-pil.

usage: contact_sheet.py OUT.png CELL_PX COLUMNS LABEL=FILE.png ..."""
import sys

from PIL import Image, ImageDraw


def backdrop(size):
    img = Image.new("RGBA", size, (40, 40, 44, 255))
    draw = ImageDraw.Draw(img)
    step = max(8, size[0] // 16)
    for y in range(0, size[1], step):
        for x in range(0, size[0], step):
            if (x // step + y // step) % 2:
                draw.rectangle([x, y, x + step - 1, y + step - 1], fill=(52, 52, 58, 255))
    return img


def main(argv):
    out, cell, cols = argv[1], int(argv[2]), int(argv[3])
    items = [a.split("=", 1) for a in argv[4:]]
    rows = (len(items) + cols - 1) // cols
    label_h = 18
    sheet = Image.new("RGBA", (cols * cell, rows * (cell + label_h)), (20, 20, 22, 255))
    draw = ImageDraw.Draw(sheet)
    for i, (label, path) in enumerate(items):
        frame = Image.open(path).convert("RGBA")
        frame.thumbnail((cell, cell), Image.LANCZOS)
        tile = backdrop((cell, cell))
        tile.alpha_composite(frame, ((cell - frame.width) // 2, (cell - frame.height) // 2))
        x, y = (i % cols) * cell, (i // cols) * (cell + label_h)
        sheet.paste(tile, (x, y))
        draw.text((x + 4, y + cell + 3), label, fill=(220, 220, 220, 255))
    sheet.convert("RGB").save(out, optimize=True)


if __name__ == "__main__":
    main(sys.argv)
