-- gkclearb (ThinkingCap/TeamChaos report §4.1): four meta-rules: face the ball, approach it, kick it out of the
-- area, or get between the ball and the opponent's net.
use(NOT(ballAhead()), "faceball")
use(AND(ballAhead(), NOT(ballClose())), "go2ball")
use(AND(ballClose(), freeToKick()), "dokick")
use(AND(ballClose(), NOT(freeToKick())), "alignbnet1")
need(1, BALL)
