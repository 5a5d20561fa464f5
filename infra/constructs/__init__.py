"""One construct per resource family: IoT fleet, robot policy, presence rule, endpoints,
the skill function, the Alexa skill, and the Lex bot with the robots' role alias."""
