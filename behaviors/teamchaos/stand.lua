-- stand: stay where you are, watching the ball (before the kickoff, while the game is stopped).
always("go", "STAY")
always("turn", "NONE")
always("strafe", "NONE")
need(1, BALL)
