-- go2ball: move to the ball location (ThinkingCap/TeamChaos report §4.3): turn towards it, go fast when it is far
-- and ahead, slow when it is close, and wait for the turn when it is off to the side.
rule(headedLeft(), "turn", "RIGHT")
rule(headedAhead(), "turn", "NONE")
rule(headedRight(), "turn", "LEFT")
rule(AND(ballAhead(), NOT(ballClose())), "go", "FAST")
rule(AND(ballAhead(), ballClose()), "go", "SLOW")
rule(NOT(ballAhead()), "go", "STAY")
always("strafe", "NONE")
need(1, BALL)
