-- gktracklms (seed 001 §4.3): look at the least recently seen landmark, through the special
-- method trackLandMarks().
chaos.trackLandMarks()
