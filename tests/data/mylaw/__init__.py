"""A user's package of blocks for the stale-cache test (tests/test_caches.py): its law calls a gain
defined in another file of the package."""
