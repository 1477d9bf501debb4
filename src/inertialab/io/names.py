"""Safe file names from data: a name taken from a record or a model file
(unit, lot, run, topic, column) becomes a file name only through :func:`safe_slug`."""

from __future__ import annotations

import hashlib
import re

#: Longest slug kept before the hash suffix (file systems allow 255 bytes).
MAX_SLUG = 64


def safe_slug(name: object, *, taken: set[str] | None = None) -> str:
    """A file-name-safe slug of ``name``: ``[A-Za-z0-9._-]`` only, no leading dot, at
    most :data:`MAX_SLUG` characters. When characters were dropped or the name was
    shortened, an 8-hex-digit hash of the original is appended so that different names
    never collide; when ``taken`` is given, a further ``-2``, ``-3`` ... suffix keeps the
    result out of it and the result is added to it.
    """
    text = str(name)
    slug = re.sub(r"[^A-Za-z0-9._-]+", "_", text).strip("._-") or "unnamed"
    slug = slug.lstrip(".")
    if slug != text or len(slug) > MAX_SLUG:
        digest = hashlib.sha256(text.encode("utf-8", "surrogatepass")).hexdigest()[:8]
        slug = f"{slug[:MAX_SLUG]}-{digest}"
    if taken is not None:
        base, k = slug, 2
        while slug in taken:
            slug = f"{base}-{k}"
            k += 1
        taken.add(slug)
    return slug
