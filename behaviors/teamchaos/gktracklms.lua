-- gktracklms (ThinkingCap/TeamChaos report §4.3): look at the least recently seen landmark, through the special
-- method trackLandMarks().
chaos.trackLandMarks()
