"""The operator console (003 ch. 5.4; 001 HILS): a live simulation in the browser with a joystick.

``oceangnc console [SCENARIO]`` serves a page (``static/``) from a FastAPI app on uvicorn
(:mod:`.server`); a :class:`~.session.Session` steps the scenario's simulation paced to wall-clock
time and applies the operator's validated commands (:mod:`.messages`). See ``docs/console.md``.
"""

from .messages import Rejected, parse_message
from .session import Session

__all__ = ["Session", "parse_message", "Rejected"]
