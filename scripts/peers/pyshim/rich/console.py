"""Plain-text `Console` with the two methods gsplat's build scripts call."""

import contextlib
import re

_MARKUP = re.compile(r"\[/?[a-z ]*\]")


class Console:
    def print(self, *objects, **_):
        print(*(_MARKUP.sub("", str(o)) for o in objects), flush=True)

    @contextlib.contextmanager
    def status(self, message, **_):
        self.print(message)
        yield
