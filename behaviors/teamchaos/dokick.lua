-- dokick: move towards the ball and kick it (ThinkingCap/TeamChaos report §4.3).
rule(headedLeft(), "turn", "RIGHT")
rule(headedAhead(), "turn", "NONE")
rule(headedRight(), "turn", "LEFT")
rule(AND(ballAhead(), NOT(ballTouching())), "go", "SLOW")
rule(AND(ballAhead(), ballTouching()), "kick", "FRONTKICK")
rule(NOT(ballAhead()), "go", "STAY")
always("strafe", "NONE")
need(1, BALL)
