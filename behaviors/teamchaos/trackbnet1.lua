-- trackbnet1 (ThinkingCap/TeamChaos report §4.1): always watch the ball; close to it, look for the opponent's net
-- too. With the ball at 400 mm ballClose is 0.7: BALL is needed at 1.0 and NET1 at 0.7.
need(1, BALL)                -- always need BALL
need(ballClose(), NET1)      -- if ballClose then need NET1
