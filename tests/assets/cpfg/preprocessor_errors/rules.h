/* productions of plant.l */
A --> F@Tx(2)
