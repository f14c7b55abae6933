/* included by plant.l */
#define LEAF @o(0.2)
