"""The base64 text of a VTK XML array, checked and decoded as VTK's reader decodes it.

VTK's XML reader decodes base64 four characters at a time: a group ending in ``=``
padding gives one or two bytes and the next group starts afresh. Some writers
(meshio for compressed arrays, older VTK) encode an array's length header on its
own, so padding may sit *inside* an array's text; that is valid. What VTK does
not do: pass over whitespace inside the text (an uncompressed array with a space
or a line break inside comes out shifted), or go on after a character outside the
alphabet or padding in the middle of a group (it stops there and leaves the rest
of the array as zeros). Both give an array of the right length and wrong values,
without an error. Here such text is `Damaged`, with the character and where it is.

`problem` checks text without decoding it (the bytes a valid text decodes to
follow from its length and its padding); `decode_groups` decodes text group by
group, the way VTK reads it, for the direct decoder (`fepost.reader.vtkdirect`).
"""

from __future__ import annotations

import pybase64

#: The 64 characters of base64.
ALPHABET = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/"
#: Whitespace a writer may put around (and the direct decoder inside) the text.
SPACE = b" \t\r\n"
#: Characters checked per slice (a multiple of 4: slices start on a group).
_SLICE = 1 << 22


class Damaged(ValueError):
    """The text is not base64 that VTK's reader decodes to the bytes it holds; the message says why."""


def chars(nbytes: int) -> int:
    """Base64 characters that encode ``nbytes`` bytes (padding included)."""
    return -(-nbytes // 3) * 4


def describe(text: bytes, start: int = 0, skip: bytes = b"", base: int = 0) -> str:
    """Why ``text[start:]`` is not base64: its first byte outside the alphabet, the padding
    and ``skip`` (named by its place in the array's text, ``text[0]`` being character ``base``)."""
    odd = text[start:].translate(None, ALPHABET + b"=" + skip)  # in order: the first is the culprit
    k = text.index(odd[:1], start)
    if text[k] in SPACE:
        return f"whitespace at character {base + k}, which VTK's reader misreads"
    return f"invalid character {chr(text[k])!r} at character {base + k}"


def _padding(text: bytes, base: int) -> int:
    """Bytes the padding of ``text`` (only alphabet and '=', ``text[0]`` being character
    ``base`` of the array's text) takes away; `Damaged` where padding does not end a group."""
    lost, k = 0, text.find(b"=")
    while k >= 0:
        pos = (base + k) % 4
        if pos == 2 and text[k + 1 : k + 2] == b"=":
            lost, k = lost + 2, k + 1
        elif pos == 3:
            lost += 1
        else:
            raise Damaged(f"'=' padding at character {base + k}, inside the data")
        k = text.find(b"=", k + 1)
    return lost


def problem(data, start: int, end: int, need: int) -> str | None:
    """What is wrong with the base64 text ``data[start:end]`` of an array that must decode to
    at least ``need`` bytes (its header words included), read as VTK reads it; None when nothing is.

    ``data``: bytes or a memory map. Whitespace around the text is passed over, inside it is
    a fault (VTK misreads it). Checked slice by slice; nothing is decoded.
    """
    end = min(end, len(data))
    while start < end and data[start] in SPACE:
        start += 1
    while end > start and data[end - 1] in SPACE:
        end -= 1
    total = 0
    for at in range(start, end, _SLICE):
        part = data[at : min(end, at + _SLICE)]
        rest = part.translate(None, ALPHABET)
        if rest:
            if rest.strip(b"="):
                return describe(part, base=at - start)
            try:
                total -= _padding(part, at - start)
            except Damaged as exc:
                return str(exc)
        total += len(part) // 4 * 3
    if (end - start) % 4:
        return f"it ends inside a group of 4 characters ({end - start} characters)"
    if total < need:
        return f"it decodes to {total} bytes, its header announces {need}"
    return None


def decode_groups(text: bytes, need: int | None = None) -> bytes:
    """``text`` (no whitespace) decoded group by group: padding ends a group, not the stream.

    With ``need``, decoding stops once that many bytes are out (the text of an appended
    array runs on into the next array's). Raise `Damaged` on anything but the alphabet
    and padding that ends a group.
    """
    out: list[bytes] = []
    got, pos, n = 0, 0, len(text)
    while pos < n and (need is None or got < need):
        stop = n if need is None else min(n, pos + chars(need - got))
        pad = text.find(b"=", pos, stop)
        if pad >= 0:
            stop = min(n, pad - (pad - pos) % 4 + 4)  # the end of the group the padding ends
        seg = text[pos:stop]
        try:
            if len(seg) % 4:
                raise ValueError
            decoded = pybase64.b64decode(seg, validate=True)
        except ValueError:
            if seg.translate(None, ALPHABET + b"="):
                raise Damaged(describe(text, pos)) from None
            if pad >= 0:
                raise Damaged(f"'=' padding at character {pad}, inside the data") from None
            raise Damaged(f"it ends inside a group of 4 characters ({n} characters)") from None
        out.append(decoded)
        got += len(decoded)
        pos = stop
    return b"".join(out)


__all__ = ["ALPHABET", "SPACE", "Damaged", "chars", "decode_groups", "describe", "problem"]
