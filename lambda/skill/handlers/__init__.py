"""One request handler class per intent (and per request type); `skill.app` registers them."""
