"""A universal ("fat") Mach-O file of thin ones, as Apple's ``lipo -create`` writes it: a big-endian
header listing each slice's CPU type, offset, size and alignment, then the slices unchanged (their
ad-hoc signatures cover the slice, not the file, so they stay valid).

Layout (``<mach-o/fat.h>``): ``fat_header {magic 0xcafebabe, nfat_arch}``, then per slice
``fat_arch {cputype, cpusubtype, offset, size, align}``, all 32-bit big-endian; each slice at an
offset that is a multiple of ``2**align``.
"""
from __future__ import annotations

import struct

FAT_MAGIC = 0xCAFEBABE
MH_MAGIC_64 = 0xFEEDFACF           # a thin 64-bit Mach-O, in the file's (little-endian) byte order
CPU_TYPE_X86_64, CPU_TYPE_ARM64 = 0x01000007, 0x0100000C
SLICE_ALIGNMENT = {CPU_TYPE_X86_64: 12, CPU_TYPE_ARM64: 14}
"""log2 of each slice's alignment in the file: the CPU's page size (4 KiB on Intel, 16 KiB on Apple
silicon), as lipo aligns them."""


def thin_cpu(library: bytes) -> tuple[int, int]:
    """(cputype, cpusubtype) of a thin little-endian 64-bit Mach-O file."""
    if len(library) < 12 or struct.unpack_from("<I", library)[0] != MH_MAGIC_64:
        raise ValueError("not a thin 64-bit little-endian Mach-O file")
    cputype, cpusubtype = struct.unpack_from("<iI", library, 4)
    return cputype, cpusubtype & 0x00FFFFFF      # the high byte holds capability bits, not the subtype


def universal(slices: list[bytes]) -> bytes:
    """The universal Mach-O file of the thin 64-bit ``slices`` (one per CPU type)."""
    cpus = [thin_cpu(library) for library in slices]
    if len({cputype for cputype, _ in cpus}) != len(cpus):
        raise ValueError("a universal file holds one slice per CPU type")
    header = struct.pack(">II", FAT_MAGIC, len(slices))
    offset = len(header) + 20 * len(slices)
    entries, body = [], b""
    for library, (cputype, cpusubtype) in zip(slices, cpus):
        align = SLICE_ALIGNMENT.get(cputype, 14)
        start = -(-offset // 2 ** align) * 2 ** align
        body += b"\0" * (start - offset) + library
        entries.append(struct.pack(">iIIII", cputype, cpusubtype, start, len(library), align))
        offset = start + len(library)
    return header + b"".join(entries) + body
