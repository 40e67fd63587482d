-- gkkeepout (ThinkingCap/TeamChaos report §4.3): turn slowly while moving until the robot is out of its net; needs
-- the most probably visible landmarks, the opponent's net included.
always("turn", "LEFT")
always("go", "SLOW")
always("strafe", "NONE")
need(1, NET1)
chaos.trackLandMarks()
