"""Where the server's long volume work runs (docs/web.md, "The page's start-up": the stalled
module requests).

A volume's work (its fingerprint, a level's encoding, the bricks' manifest, block ranges, brick
encodings and their encoding's choice) takes seconds to tens of seconds on a 512^3 volume under
load, and a page's streaming queues dozens of such jobs. On asyncio's default executor they would
queue ahead of the short file work that shares it: a page's static file gzip'd again
(serve_static.py: a new version of the file) and aiohttp's own FileResponse (its stat, open and
reads), so a page's module request would wait for all of them. The volume work gets its own pool
here, of the default pool's size, and the default executor keeps only the short file work.
"""
import os
from concurrent.futures import ThreadPoolExecutor

# The size asyncio's default executor has (Python 3.8+): the volume work as parallel as it was.
VOLUME_WORK = ThreadPoolExecutor(max_workers=min(32, (os.cpu_count() or 1) + 4),
                                 thread_name_prefix="mediso-volume")
