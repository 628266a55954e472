#!/usr/bin/env python3
"""crash_image.py IMAGE OUT - lays out in OUT (a new directory) what a machine would find of the
directory that tests/fault/fault_shim.c watched (PORO_CRASH_ROOT) after a power loss at the moment
the watched processes stopped: the entries of each directory as of its last fsync, each file's
bytes as of its last fsync (an entry whose file was never fsynced is an empty file), and nothing
that was never made durable. Exits 1 when IMAGE holds no image (nothing was ever fsynced)."""
import os
import shutil
import sys


def lay_out(image, key, out, depth=0):
    os.makedirs(out, exist_ok=True)
    listing = os.path.join(image, ".dirs", key)
    if not os.path.exists(listing) or depth > 64:
        return
    with open(listing) as f:
        for line in f:
            kind, hex_name, child = line.split()
            name = bytes.fromhex(hex_name).decode("utf-8", "surrogateescape")
            path = os.path.join(out, name)
            if kind == "d":
                lay_out(image, child, path, depth + 1)
            else:
                data = os.path.join(image, ".data", child)
                if os.path.exists(data):
                    shutil.copyfile(data, path)
                else:
                    open(path, "wb").close()
                os.chmod(path, 0o600)


def main():
    image, out = sys.argv[1], sys.argv[2]
    root = os.path.join(image, ".root")
    if not os.path.exists(root):
        print("crash_image: no image in '%s'" % image, file=sys.stderr)
        return 1
    with open(root) as f:
        key = f.read().strip()
    lay_out(image, key, out)
    os.chmod(out, 0o700)
    return 0


if __name__ == "__main__":
    sys.exit(main())
