-- gkscanobj (ThinkingCap/TeamChaos report §4.3): scan the field on the spot until the ball is found, looking at
-- landmarks and nets in turn.
use(1, "lookball")
use(1, "gktracklms")
