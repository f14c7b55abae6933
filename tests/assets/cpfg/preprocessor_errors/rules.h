/* productions of plant.l */
A --> F@bo(2)
