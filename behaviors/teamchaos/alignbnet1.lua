-- alignbnet1: move until the robot, the ball and the opponent's net (NET1) are aligned
-- (ThinkingCap/TeamChaos report §4.3). Strafing right makes the near ball drift left in view faster than the far
-- net, so a net seen left of the ball calls for a step to the right, and the other way round;
-- meanwhile the robot keeps facing the ball.
rule(netLeftOfBall(), "strafe", "RIGHT")
rule(netBehindBall(), "strafe", "NONE")
rule(netRightOfBall(), "strafe", "LEFT")
rule(headedLeft(), "turn", "RIGHT")
rule(headedAhead(), "turn", "NONE")
rule(headedRight(), "turn", "LEFT")
always("go", "STAY")
need(1, BALL)
need(1, NET1)
