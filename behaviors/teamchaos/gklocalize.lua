-- gklocalize (ThinkingCap/TeamChaos report §4.3): stand still and look for the closest landmarks and the nets
-- for a better position estimate.
always("go", "STAY")
always("turn", "NONE")
always("strafe", "NONE")
use(1, "gktracklms")
need(0.6, NET1)
need(0.6, NET2)
