-- faceball: turn on the spot until the ball is straight ahead (ThinkingCap/TeamChaos report §4.3, §5.2).
rule(headedLeft(), "turn", "RIGHT")
rule(headedAhead(), "turn", "NONE")
rule(headedRight(), "turn", "LEFT")
always("go", "STAY")
always("strafe", "NONE")
need(1, BALL)
