"""What the simulator knows beyond the skill's model: Alexa's built-in intents and the world.

Real Alexa trains its built-in intents (help, stop, cancel, ...) and its out-of-domain
detection on Amazon's own data; the skill's model lists those intents without samples. The
simulator stands in for that data with the phrases below, written as templates (the syntax
of `vahr.skill_model.templates`): the usual ways of asking for help or stopping, and
everyday requests a voice assistant hears that this skill does not handle. The out-of-domain
phrases train `AMAZON.FallbackIntent`; none of them is, or is derived from, a sentence of the
development set (`vahr nlu --eval`).
"""

from __future__ import annotations

from vahr.skill_model.templates import expand

BUILT_IN_TEMPLATES: dict[str, tuple[str, ...]] = {
    "AMAZON.HelpIntent": (
        "[please] help [me|me out|please]",
        "(what|how) can i (say|do|ask)",
        "what can you do [for me]",
        "how does (this|it) work",
        "i need (help|some help|assistance)",
        "what are my options",
        "(what|which) commands (are there|can i use|do you know)",
        "i don't know what to (say|do)",
    ),
    "AMAZON.StopIntent": (
        "stop",
        "off",
        "shut up",
        "be quiet",
        "(that's|that is) (all|it|enough)",
        "i'm done",
        "(we're|we are) done",
        "enough",
    ),
    # Amazon lists "never mind" with cancel, not with stop (the built-in intents' reference).
    "AMAZON.CancelIntent": (
        "cancel [that|it|this|please]",
        "never mind",
        "forget (it|that|about it)",
        "nothing",
        "no thanks",
        "don't (bother|worry about it)",
        "scratch that",
    ),
    "AMAZON.NavigateHomeIntent": ("go home", "go to the home screen", "(home|main) (screen|menu)"),
}

OUT_OF_DOMAIN_TEMPLATES: tuple[str, ...] = (
    "(play|put on) [some] (music|jazz|the radio|a song|my playlist|a podcast)",
    "(set|start) a timer for (five|ten|twenty) minutes",
    "(set|wake me up with) an alarm for (six|seven) [am|in the morning]",
    "what time is it [now|in tokyo|in london]",
    "what's the date [today]",
    "(what|which) (day|month|year) is it [today]",
    "how much (does|do) (a robot|the robots|it|this) cost",
    "can (the robots|a robot|they|it) (climb stairs|open doors|see me|hear me|talk|swim|fly|lift "
    "heavy boxes|carry two packages|go outside)",
    "how (fast|heavy|tall|big|strong|old) (are the robots|is a robot|are they|is it)",
    "are (the zones|the robots) (far apart|close together|next to each other|the same)",
    "(who|when) (made|built|designed|programmed) (the robots|this|it|them)",
    "(what's|what is) (new|happening|on tv|in the news|for dinner) [today|tonight]",
    "do i have (any meetings|anything on|any appointments|plans) [today|tomorrow|tonight]",
    "(any|are there any) good (films|movies|shows) on [tonight|today]",
    "(am i|are we) doing (this|it|okay|well) [right]",
    "is the (experiment|study|session|test) (over|done|finished) [yet]",
    "(what did you say|say that again|come again|pardon)",
    "how long (has it been|will (this|it) take|do we have|is (this|the session))",
    "(how's|how is) it going [today|so far]",
    "(get|order) me (a|some) (burger|pizza|coffee|sandwich|lunch) [delivered]",
    "tell me a (joke|story|fun fact|riddle)",
    "(turn|switch) (on|off) the (lights|lamp|tv|heating|fan)",
    "(dim|brighten) the lights [in the kitchen]",
    "(add|put) (milk|eggs|bread|coffee) (to|on) my shopping list",
    "what's on my (calendar|schedule|agenda) [today|tomorrow]",
    "(call|text|message) (mom|dad|my sister|the office)",
    "how (tall|old|far away|big) is (the moon|mount everest|the eiffel tower)",
    "who (won|is winning) the (game|match|election) [last night]",
    "what's the capital of (france|peru|canada)",
    "(translate|how do you say) (hello|thank you) in (spanish|german|french)",
    "read me the (news|headlines)",
    "(turn|volume) (up|down) [the volume]",
    "(order|buy) [me] (a pizza|more paper towels|batteries)",
    "how do i (bake|make) (bread|pancakes|a cake)",
    "what's (two|five) (plus|times) (three|seven)",
    "spell (necessary|rhythm)",
    "define (serendipity|entropy)",
    "who (are you|made you|is your favorite singer)",
    "what's your (name|favorite color)",
    "(i'm|i am) (hungry|tired|bored)",
    "good (morning|night|evening)",
    "how are you [today]",
    "(sing|recite) (a song|a poem|happy birthday)",
    "(open|launch) (spotify|netflix|youtube)",
    "(lock|unlock) the (front door|car)",
    "where is the (nearest|closest) (gas station|pharmacy|coffee shop)",
    "how long is my commute [today]",
    "remind me to (call mom|take out the trash|buy milk) [tomorrow|later]",
    "what's the traffic like [today]",
    "flip a coin",
    "roll a die",
    "what's the score of the (football|baseball) game",
    "how many (ounces|cups) (are|is) in a (pound|liter)",
    "(find|show) me a (recipe|movie|restaurant)",
    "what movies are playing [tonight]",
    "what's the stock price of (amazon|apple)",
    "make a (note|list)",
    "what's the meaning of life",
    "(bake|make) me (a sandwich|some coffee|breakfast)",
    "the puzzle is (hard|almost done)",
    "where did i put the (puzzle piece|corner piece)",
    "this (piece|puzzle) doesn't fit",
    "(hmm|okay|well) let me think",
    "i'll do the puzzle (now|first)",
    "can you (dance|draw|paint)",
    "(charge|clean|paint|repair) the robots",
    "make the robots (dance|sing|spin)",
    "(how many|which) robots (do you have|are there)",
    "who built the robots",
    "what is a robot",
    "(the|my) (keyboard|mouse|screen) (is broken|is not working)",
    "(shall|should) we take a break",
    # Questions about the world open with the same words as questions about the robots.
    "(where|what) (is|are) (the|my|your|our) (keys|phone|wallet|bathroom|kitchen|car|office"
    "|boss|password|address|budget|plan)",
    "(how|what) is the (economy|stock market|new job|project|team|family|baby) (doing|like)",
    "what is the (boiling point|speed|weight|size|color) of (water|sound|gold|the earth)",
    "(what|how) (is|are) (you|things|your day|the kids|your family) (doing|going|up to)",
    "(thanks|thank you) [a lot|so much|very much]",
    "(what's up|what's new|what's happening)",
    "(here|off) we go",
    "(is|are) (it|we|they) (time|ready|late) [yet]",
    # Talk about weather and deliveries in general, not the weather now or a robot's job.
    "(do|don't) you (like|love|hate|enjoy|prefer) (rain|rainy weather|sunny weather|the sun"
    "|sunshine|storms|summer|winter)",
    "(what's|what is) your (favorite|favourite|least favorite) (season|weather|kind of weather"
    "|time of year)",
    "(how|why) (do|does) (weather forecasts|the weather|rain|clouds|rainbows|thunder) (work"
    "|happen|form)",
    "(why is|what makes) the sky (blue|grey|gray)",
    "(who|which company|what company) (delivers|ships|makes) the most (packages|parcels)",
    "(how|why) (do|does) (package delivery|the post office|shipping|couriers) work",
    # Questions about what the robots are, which name them but ask nothing of them.
    "(what|which) (programming language|software|operating system|sensors|motors|batteries)"
    " (do|does) (the robots|these robots|the placebots|placebot one) (use|run on|have)",
    "(are|is) (the robots|these robots|the placebots|placebot two) (running on|built with|made"
    " of|powered by) (ros|linux|batteries|python|plastic)",
    "(what|who) (is|are) (a placebot|the placebots|placebot one) [anyway|exactly|really]",
    "(how|why) (do|does|did) (meteorologists|forecasters|weather stations|satellites) "
    "(predict|forecast|measure|track) the weather",
    "(what's|what is) the difference between (weather and climate|rain and drizzle|a shower and"
    " a storm)",
)


def built_in_phrases() -> dict[str, list[str]]:
    """Each built-in intent's phrases, expanded."""
    return {
        intent: [sentence for template in templates for sentence in expand(template)]
        for intent, templates in BUILT_IN_TEMPLATES.items()
    }


def out_of_domain_phrases() -> list[str]:
    """Everyday requests the skill does not handle, expanded."""
    return [sentence for template in OUT_OF_DOMAIN_TEMPLATES for sentence in expand(template)]
